#pragma once
/// @file clustering.hpp
/// Steps 6-7 of the paper: k-means with k weights per pixel (Algorithm 1), read as
/// ../shared/docs/ALGORITHM.md settles it. ClusterState is the one object that lives across
/// frames: centres, per-pixel weights mu, tau, the random generator and scratch buffers.
#include <cstdint>
#include <random>
#include <vector>

#include "wul3d/cloud.hpp"
#include "wul3d/image.hpp"
#include "wul3d/weights.hpp"

namespace wul3d {

/// Parameters of the weighted clustering. Ranges are the paper's (section II.C); validate()
/// enforces them.
struct ClusterParams {
    int k = 7;               ///< clusters; 1 <= k <= 65535 (labels are 16-bit) and <= valid points
    float alpha = 0.0033f;   ///< colour scale, eq. (4); paper range [0.002, 0.1]; colours in 0-255
    float delta = 0.9967f;   ///< position scale, eq. (4); > 0, alpha + delta <= 1 (eq. 5); metres
    float gamma = 0.0001f;   ///< normal scale, eq. (6); paper range [0.0001, 0.01]
    float psi = 1.0f;        ///< weight increment, eq. (2); (0, 1]
    int iters = 1;           ///< k-means iterations per frame; >= 1 (the paper: 1, one per frame)
    int stride = 1;          ///< sampling stride in pixels; >= 1 (the paper: "sampling of one")
    std::uint64_t seed = 1;  ///< k-means++ seeding; same seed and input give the same labels

    /// The authors' values: alpha 0.0033, delta 1 - alpha, gamma 0.0001, psi 1, k 7.
    static ClusterParams paper();
    void validate() const;  ///< throws ParamError naming the field, value and range
};

/// Cluster centres, structure of arrays, k entries. Position and colour are the mean of the
/// points that chose the centre; the normal is their mean normal, renormalized (the usual
/// k-means choice; the authors' code took the normal of the point nearest the mean).
struct Centres {
    std::vector<float> x, y, z;     ///< metres
    std::vector<float> r, g, b;     ///< 0-255
    std::vector<float> nx, ny, nz;  ///< unit, or all 0 when none of the points had a normal
    std::vector<std::int64_t> count;  ///< points that chose this centre in the last iteration

    int k() const { return static_cast<int>(x.size()); }
    void resize(int k);
};

/// What one frame did; observability as data (the CLI's summary reads it).
struct FrameStats {
    std::int64_t tau = 0;            ///< frames clustered so far, this one included (eq. 3)
    std::size_t points = 0;          ///< points clustered (active pixels on the sampled grid)
    bool seeded = false;             ///< k-means++ ran on this frame
    int reseeded = 0;                ///< empty clusters re-seeded on this frame
    double mean_f = 0;               ///< mean distance f (eq. 6) of the points to their winner
    /// Milliseconds in each phase of step(): counting the active points and k-means++
    /// seeding, distances and arg-min with the centre sums (eq. 6, every iteration), weight
    /// update and labels (eq. 2, 7, 8), centre update and re-seeding, full-resolution labels.
    /// For the profile in bench/.
    struct Phases {
        double seeding = 0, assign = 0, weights = 0, centres = 0, labels = 0;
    } ms;
};

/// The feature-space distance f of eq. (6) between a point and a centre, used by tests and
/// by the hot loop's reference. cos_theta = n_i . n_c; pass has_normals = false when either
/// normal is missing (the normal term is then 0).
double distance_f(const ClusterParams& p, float px, float py, float pz, float pr, float pg,
                  float pb, float cx, float cy, float cz, float cr, float cg, float cb,
                  double cos_theta, bool has_normals, bool use_color = true);

/// State across frames. Construct once per sequence; step() once per frame.
class ClusterState {
public:
    explicit ClusterState(const ClusterParams& params);  ///< validates params

    /// One frame of Algorithm 1. On the first frame (or after reset) seeds with k-means++.
    /// Then `iters` times: each active point picks the centre with the smallest f (eq. 6),
    /// centres move to the mean of their points, empty centres are re-seeded at the points
    /// farthest from their centre. After the last assignment every point's weights take
    /// psi for its winner (eq. 2, 7, 8) and its label is the arg-max weight. Pixels not
    /// active this frame keep their weights and get label 0.
    /// `active` is the full-resolution mask from background.hpp. Throws InputError if the
    /// first frame has fewer active points than k. Labels come back at full resolution;
    /// with stride s > 1, pixel (u, v) takes the label of grid point (u / s, v / s) when it
    /// is itself active.
    FrameStats step(const OrganizedCloud& cloud, const NormalMap& normals,
                    const std::vector<std::uint8_t>& active, LabelImage& labels);

    /// Forget centres and weights: the next step() seeds again.
    void reset();

    const ClusterParams& params() const { return params_; }
    const Centres& centres() const { return centres_; }
    std::int64_t tau() const { return tau_; }
    bool seeded() const { return seeded_; }

    /// The sampled grid the weights live on: ceil(width / stride) x ceil(height / stride).
    int grid_width() const { return grid_w_; }
    int grid_height() const { return grid_h_; }
    /// Grid index of full-resolution pixel (u, v).
    int grid_index(int u, int v) const {
        return (v / params_.stride) * grid_w_ + (u / params_.stride);
    }
    /// The kept weights mu of grid point g (sum 1, or all 0 if never seen).
    const PixelWeights& weights(int g) const { return mu_[static_cast<std::size_t>(g)]; }
    /// The winner (0-based centre with the smallest f) of each grid point in the last frame,
    /// -1 where the point was not active. For tests and tools: it lets a caller replay the
    /// weight update with another representation.
    void last_winners(std::vector<int>& per_grid_point) const;

private:
    struct Grid;  ///< this frame's cloud, normals and mask on the sampled grid (clustering.cpp)
    enum class FToPoint { Set, Lower, Potential };

    void allocate(int width, int height);
    std::size_t count_active(const Grid& grid) const;
    std::size_t nth_active(const Grid& grid, std::size_t r) const;  ///< grid index of the r-th
    void seed_kmeanspp(const Grid& grid);
    /// Eq. (6) arg-min of every active point into winner_ and f_, with the centre sums.
    void assign(const Grid& grid);
    double move_centres();  ///< centres from assign's sums; returns the mean f
    int reseed_empty(const Grid& grid);
    void update_weights_and_labels();
    // helpers of seeding and re-seeding
    void set_centre(int j, const Grid& grid, std::size_t g);
    /// f of every active point to each of the n grid points c[0..n): Set (n = 1) stores it
    /// in f_, Lower (n = 1) keeps the smaller of it and f_, Potential puts the sum of
    /// min(f_, f)^2 for c[t] into potential[t] and stores nothing. One pass over the points.
    void f_to_points(const Grid& grid, const std::size_t* c, int n, FToPoint use, double* potential);
    std::size_t sample_by_f_squared(const Grid& grid);
    void add_centre(int j, const Grid& grid);  ///< centre j by the greedy D^2 rule; lowers f_
    bool centre_has_normal(int j) const {
        return centres_.nx[j] != 0.0f || centres_.ny[j] != 0.0f || centres_.nz[j] != 0.0f;
    }

    ClusterParams params_;
    Centres centres_;
    std::vector<PixelWeights> mu_;  ///< one per grid point
    std::int64_t tau_ = 0;
    bool seeded_ = false;
    int width_ = 0, height_ = 0, grid_w_ = 0, grid_h_ = 0;
    std::mt19937_64 rng_;

    // Per grid point, sized once per resolution (the points themselves are read from the
    // cloud block by block, never copied whole: 8 bytes a point besides the weights).
    std::vector<std::uint16_t> winner_;      ///< 0-based winner of the last assignment, 0xffff: inactive
    std::vector<float> f_;                   ///< f to that winner (while seeding: to the nearest centre); 0: inactive
    std::vector<std::uint16_t> grid_label_;  ///< arg-max weight + 1, 0 = none
    std::vector<double> chunk_sums_;         ///< assign's centre sums per fixed chunk of points
    std::vector<float> centre_normal_;       ///< 1 where centre j has a normal
    std::size_t n_ = 0;       ///< active grid points this frame
    bool use_color_ = true;   ///< false for depth-only frames: the colour term drops out
};

}  // namespace wul3d
