#include "wul3d/clustering.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "param_check.hpp"
#include "wul3d/error.hpp"

namespace wul3d {

// ---- parameters -----------------------------------------------------------------------

ClusterParams ClusterParams::paper() {
    ClusterParams p;
    p.k = 7;
    p.alpha = 0.0033f;      // the authors' public code, see ALGORITHM.md step 6
    p.delta = 1 - p.alpha;  // eq. (5) at equality
    p.gamma = 0.0001f;
    p.psi = 1.0f;
    p.iters = 1;
    p.stride = 1;
    return p;
}

namespace {
template <class T>
void require(bool ok, const char* name, T value, const char* range) {
    detail::require_param(ok, "", name, value, range);
}
}  // namespace

void ClusterParams::validate() const {
    require(k >= 1 && k <= 65535, "k", k, "in [1, 65535]");
    require(alpha >= 0.002f && alpha <= 0.1f, "alpha", alpha,
            "in [0.002, 0.1] (the paper's range, section II.C)");
    require(delta > 0 && alpha + delta <= 1.0f + 1e-6f, "delta", delta,
            "> 0 with alpha + delta <= 1 (paper eq. 5)");
    require(gamma >= 0.0001f && gamma <= 0.01f, "gamma", gamma,
            "in [0.0001, 0.01] (the paper's range, section II.C)");
    require(psi > 0 && psi <= 1.0f, "psi", psi, "in (0, 1] (paper eq. 2)");
    require(iters >= 1 && iters <= 1000, "iters", iters, "in [1, 1000]");
    require(stride >= 1 && stride <= 64, "stride", stride, "in [1, 64]");
}

void Centres::resize(int k) {
    for (auto* a : {&x, &y, &z, &r, &g, &b, &nx, &ny, &nz}) a->assign(k, 0.0f);
    count.assign(k, 0);
}

// ---- the two equations, by themselves ---------------------------------------------------

double distance_f(const ClusterParams& p, float px, float py, float pz, float pr, float pg,
                  float pb, float cx, float cy, float cz, float cr, float cg, float cb,
                  double cos_theta, bool has_normals, bool use_color) {
    const double dx = px - cx, dy = py - cy, dz = pz - cz;
    const double dr = pr - cr, dg = pg - cg, db = pb - cb;
    const double a = use_color ? p.alpha : 0.0, d = p.delta;
    // Paper eq. (4): dist = sqrt(delta^2 |dxyz|^2 + alpha^2 |drgb|^2)
    const double dist = std::sqrt(d * d * (dx * dx + dy * dy + dz * dz) +
                                  a * a * (dr * dr + dg * dg + db * db));
    // Paper eq. (6): f = dist + gamma (1 - cos theta)
    return dist + (has_normals ? p.gamma * (1.0 - cos_theta) : 0.0);
}

int update_weights(float* mu, int k, int winner, float psi) {
    // Paper eq. (2): delta_winner += psi; eq. (7)-(8): L1-normalize (ALGORITHM.md step 7).
    float sum = 0;
    for (int j = 0; j < k; ++j) sum += mu[j];
    mu[winner] += psi;
    const float inv = 1.0f / (sum + psi);
    for (int j = 0; j < k; ++j) mu[j] *= inv;
    int best = winner;  // ties go to the newest evidence
    for (int j = 0; j < k; ++j)
        if (mu[j] > mu[best]) best = j;
    return best;
}

int update_weights(PixelWeights& w, int winner, float psi) {
    constexpr int S = PixelWeights::kSlots;
    // A pixel whose whole weight is already on the winner stays so: (1 + psi) / (1 + psi).
    // That is every pixel of a still scene, so it is worth checking first.
    if (w.mu[0] == static_cast<std::uint16_t>(PixelWeights::kOne) && w.cluster[0] == winner)
        return winner;
    float m[S];
    float sum = 0;
    int slot = -1, smallest = 0;
    for (int s = 0; s < S; ++s) {
        m[s] = w.mu[s];
        sum += m[s];
        if (w.mu[s] > 0 && w.cluster[s] == winner) slot = s;
        if (w.mu[s] < w.mu[smallest]) smallest = s;
    }
    if (slot < 0) {  // the winner is not kept: it takes the smallest slot, whose weight drops
        slot = smallest;
        sum -= m[slot];
        m[slot] = 0;
        w.cluster[slot] = static_cast<std::uint16_t>(winner);
    }
    // Paper eq. (2), then (7)-(8) on the kept weights, in units of kOne.
    m[slot] += psi * PixelWeights::kOne;
    const float scale = PixelWeights::kOne / (sum + psi * PixelWeights::kOne);
    for (int s = 0; s < S; ++s)
        w.mu[s] = static_cast<std::uint16_t>(std::min(PixelWeights::kOne, m[s] * scale + 0.5f));
    int best = slot;  // ties go to the newest evidence
    for (int s = 0; s < S; ++s)
        if (w.mu[s] > w.mu[best]) best = s;
    const std::uint16_t label = w.cluster[best];
    if (w.mu[best] == static_cast<std::uint16_t>(PixelWeights::kOne) && best != 0) {
        std::swap(w.cluster[0], w.cluster[best]);  // keeps the fast path above reachable
        std::swap(w.mu[0], w.mu[best]);
    }
    return label;
}

// ---- ClusterState -----------------------------------------------------------------------

namespace {
// Points are split into this many fixed blocks for the centre sums; the sums are reduced in
// block order, so results do not depend on the number of threads.
constexpr int kBlocks = 64;
constexpr int kSums = 11;  // x y z r g b nx ny nz, count, f
}  // namespace

void ClusterState::Points::resize(std::size_t n) {
    grid.resize(n);
    for (auto* a : {&x, &y, &z, &r, &g, &b, &nx, &ny, &nz, &f}) a->resize(n);
    has_normal.resize(n);
    winner.resize(n);
}

ClusterState::ClusterState(const ClusterParams& params) : params_(params) {
    params_.validate();
    centres_.resize(params_.k);
    rng_.seed(params_.seed);
}

void ClusterState::reset() {
    std::fill(mu_.begin(), mu_.end(), PixelWeights{});
    centres_.resize(params_.k);
    tau_ = 0;
    seeded_ = false;
    rng_.seed(params_.seed);
}

void ClusterState::allocate(int width, int height) {
    width_ = width;
    height_ = height;
    const int s = params_.stride;
    grid_w_ = (width + s - 1) / s;
    grid_h_ = (height + s - 1) / s;
    const std::size_t grid = static_cast<std::size_t>(grid_w_) * grid_h_;
    mu_.assign(grid, PixelWeights{});
    grid_label_.assign(grid, 0);
    row_count_.assign(grid_h_ + 1, 0);
    pts_.resize(grid);
    cumulative_.resize(grid);
    candidate_f_.resize(grid);
    best_candidate_f_.resize(grid);
    block_sums_.assign(static_cast<std::size_t>(kBlocks) * params_.k * kSums, 0.0);
    reset();
}

void ClusterState::gather(const OrganizedCloud& cloud, const NormalMap& normals,
                          const std::vector<std::uint8_t>& active) {
    const int s = params_.stride, W = cloud.width;
    // Two passes over grid rows (count, then fill at prefix offsets) keep the packed order
    // the raster order whatever the thread count.
#pragma omp parallel for schedule(static)
    for (int gv = 0; gv < grid_h_; ++gv) {
        const std::size_t row = static_cast<std::size_t>(gv) * s * W;
        int c = 0;
        for (int gu = 0; gu < grid_w_; ++gu) c += active[row + static_cast<std::size_t>(gu) * s];
        row_count_[gv + 1] = c;
    }
    row_count_[0] = 0;
    for (int gv = 0; gv < grid_h_; ++gv) row_count_[gv + 1] += row_count_[gv];
    n_ = static_cast<std::size_t>(row_count_[grid_h_]);

#pragma omp parallel for schedule(static)
    for (int gv = 0; gv < grid_h_; ++gv) {
        std::size_t i = static_cast<std::size_t>(row_count_[gv]);
        const std::size_t row = static_cast<std::size_t>(gv) * s * W;
        for (int gu = 0; gu < grid_w_; ++gu) {
            const std::size_t p = row + static_cast<std::size_t>(gu) * s;
            if (!active[p]) continue;
            pts_.grid[i] = gv * grid_w_ + gu;
            pts_.x[i] = cloud.x[p];
            pts_.y[i] = cloud.y[p];
            pts_.z[i] = cloud.z[p];
            pts_.r[i] = cloud.r[p];
            pts_.g[i] = cloud.g[p];
            pts_.b[i] = cloud.b[p];
            pts_.nx[i] = normals.nx[p];
            pts_.ny[i] = normals.ny[p];
            pts_.nz[i] = normals.nz[p];
            pts_.has_normal[i] = normals.valid[p];
            ++i;
        }
    }
}

namespace {

/// What the assignment kernel reads: packed points and centres, structure of arrays.
struct AssignInputs {
    const float *x, *y, *z, *r, *g, *b, *nx, *ny, *nz;
    const std::uint8_t* has_normal;
    const float *cx, *cy, *cz, *cr, *cg, *cb, *cnx, *cny, *cnz;
    const float* centre_has_normal;  ///< 1 or 0 per centre
    int k;
    float d2, a2, gamma;             ///< delta^2, alpha^2 (0 without colour), gamma
};

constexpr std::size_t kAssignBlock = 256;

/// Winner (unless null) and f of points [i0, i0 + m), m <= kAssignBlock. Points in a block, centres in
/// the outer loop (as FAISS does): the inner loop runs over contiguous points and
/// vectorizes whatever k is. Built twice, for AVX2 and for baseline x86-64, picked at load
/// time: baseline SSE2 has no blend, so GCC keeps the arg-min scalar there.
#if defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx2", "default")))
#endif
void assign_block(const AssignInputs& in, std::size_t i0, std::size_t m, int* winner,
                  float* fmin) {
    float best_f[kAssignBlock], gp[kAssignBlock];
    int best[kAssignBlock];
    for (std::size_t q = 0; q < m; ++q) {
        best_f[q] = INFINITY;
        best[q] = 0;
        gp[q] = in.has_normal[i0 + q] ? in.gamma : 0.0f;
    }
    const float *X = in.x + i0, *Y = in.y + i0, *Z = in.z + i0;
    const float *R = in.r + i0, *G = in.g + i0, *B = in.b + i0;
    const float *NX = in.nx + i0, *NY = in.ny + i0, *NZ = in.nz + i0;
    for (int j = 0; j < in.k; ++j) {
        const float qx = in.cx[j], qy = in.cy[j], qz = in.cz[j];
        const float qr = in.cr[j], qg = in.cg[j], qb = in.cb[j];
        const float qnx = in.cnx[j], qny = in.cny[j], qnz = in.cnz[j];
        const float qn = in.centre_has_normal[j];
        for (std::size_t q = 0; q < m; ++q) {
            const float dx = X[q] - qx, dy = Y[q] - qy, dz = Z[q] - qz;
            const float dr = R[q] - qr, dg = G[q] - qg, db = B[q] - qb;
            // Eq. (4); the square root stays: with eq. (6)'s additive normal term the
            // arg-min of f is not the arg-min of the squared distance.
            const float dist = std::sqrt(in.d2 * (dx * dx + dy * dy + dz * dz) +
                                         in.a2 * (dr * dr + dg * dg + db * db));
            const float cos_theta = NX[q] * qnx + NY[q] * qny + NZ[q] * qnz;
            const float f = dist + gp[q] * qn * (1.0f - cos_theta);  // eq. (6)
            const bool better = f < best_f[q];
            best_f[q] = better ? f : best_f[q];
            best[q] = better ? j : best[q];
        }
    }
    for (std::size_t q = 0; q < m; ++q) fmin[i0 + q] = best_f[q];
    if (winner)
        for (std::size_t q = 0; q < m; ++q) winner[i0 + q] = best[q];
}

}  // namespace

void ClusterState::set_centre(int j, std::size_t i) {
    centres_.x[j] = pts_.x[i];
    centres_.y[j] = pts_.y[i];
    centres_.z[j] = pts_.z[i];
    centres_.r[j] = pts_.r[i];
    centres_.g[j] = pts_.g[i];
    centres_.b[j] = pts_.b[i];
    centres_.nx[j] = pts_.nx[i];
    centres_.ny[j] = pts_.ny[i];
    centres_.nz[j] = pts_.nz[i];
    centres_.count[j] = 0;
}

void ClusterState::f_to_point(std::size_t c, std::vector<float>& out) const {
    // Point c as the one centre of the assignment kernel.
    const float one = pts_.has_normal[c] ? 1.0f : 0.0f;
    const AssignInputs in{pts_.x.data(), pts_.y.data(), pts_.z.data(), pts_.r.data(),
                          pts_.g.data(), pts_.b.data(), pts_.nx.data(), pts_.ny.data(),
                          pts_.nz.data(), pts_.has_normal.data(),
                          &pts_.x[c], &pts_.y[c], &pts_.z[c], &pts_.r[c], &pts_.g[c], &pts_.b[c],
                          &pts_.nx[c], &pts_.ny[c], &pts_.nz[c], &one, 1,
                          params_.delta * params_.delta,
                          use_color_ ? params_.alpha * params_.alpha : 0.0f, params_.gamma};
    const std::size_t n = n_;
    const auto blocks = static_cast<std::ptrdiff_t>((n + kAssignBlock - 1) / kAssignBlock);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t blk = 0; blk < blocks; ++blk) {
        const std::size_t i0 = static_cast<std::size_t>(blk) * kAssignBlock;
        assign_block(in, i0, std::min(kAssignBlock, n - i0), nullptr, out.data());
    }
}

std::size_t ClusterState::sample_by_f_squared() {
    // Greedy k-means++ (Arthur & Vassilvitskii 2007, section 6): draw a few candidates with
    // probability proportional to f^2, f being the distance to the nearest centre chosen so
    // far, and keep the one that lowers the total f^2 most. Its distances are left in
    // best_candidate_f_. Sums run serially or in fixed blocks, in order, so the choice does
    // not depend on the thread count.
    double total = 0;
    for (std::size_t i = 0; i < n_; ++i) {
        total += static_cast<double>(pts_.f[i]) * pts_.f[i];
        cumulative_[i] = total;
    }
    const int trials = 2 + static_cast<int>(std::log(static_cast<double>(params_.k)));
    std::size_t best = 0;
    double best_potential = INFINITY;
    for (int t = 0; t < trials; ++t) {
        std::size_t c;
        if (total > 0) {
            const double target = std::uniform_real_distribution<double>(0.0, total)(rng_);
            c = static_cast<std::size_t>(
                std::upper_bound(cumulative_.begin(), cumulative_.begin() + n_, target) -
                cumulative_.begin());
            c = std::min(c, n_ - 1);
        } else {  // every point sits on a centre: any point will do
            c = std::uniform_int_distribution<std::size_t>(0, n_ - 1)(rng_);
        }
        f_to_point(c, candidate_f_);
        double block_potential[kBlocks];
#pragma omp parallel for schedule(static)
        for (int blk = 0; blk < kBlocks; ++blk) {
            double sum = 0;
            for (std::size_t i = n_ * blk / kBlocks; i < n_ * (blk + 1) / kBlocks; ++i) {
                const double f = std::min(pts_.f[i], candidate_f_[i]);
                sum += f * f;
            }
            block_potential[blk] = sum;
        }
        double potential = 0;
        for (double p : block_potential) potential += p;
        if (potential < best_potential) {
            best_potential = potential;
            best = c;
            candidate_f_.swap(best_candidate_f_);
        }
    }
    return best;
}

void ClusterState::add_centre(int j) {
    set_centre(j, sample_by_f_squared());
    const auto n = static_cast<std::ptrdiff_t>(n_);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < n; ++i) pts_.f[i] = std::min(pts_.f[i], best_candidate_f_[i]);
}

void ClusterState::seed_kmeanspp() {
    const std::size_t first = std::uniform_int_distribution<std::size_t>(0, n_ - 1)(rng_);
    set_centre(0, first);
    f_to_point(first, pts_.f);
    for (int j = 1; j < params_.k; ++j) add_centre(j);
}

void ClusterState::assign() {
    const int k = params_.k;
    // 1 where the centre has a normal, so that the normal term drops out for it (eq. 6
    // needs both normals).
    for (int j = 0; j < k; ++j) centre_normal_[j] = centre_has_normal(j) ? 1.0f : 0.0f;
    const AssignInputs in{pts_.x.data(),  pts_.y.data(),  pts_.z.data(),  pts_.r.data(),
                          pts_.g.data(),  pts_.b.data(),  pts_.nx.data(), pts_.ny.data(),
                          pts_.nz.data(), pts_.has_normal.data(),
                          centres_.x.data(), centres_.y.data(), centres_.z.data(),
                          centres_.r.data(), centres_.g.data(), centres_.b.data(),
                          centres_.nx.data(), centres_.ny.data(), centres_.nz.data(),
                          centre_normal_.data(), k, params_.delta * params_.delta,
                          use_color_ ? params_.alpha * params_.alpha : 0.0f, params_.gamma};
    int* winner = pts_.winner.data();
    float* fmin = pts_.f.data();
    const std::size_t n = n_;
    const auto blocks = static_cast<std::ptrdiff_t>((n + kAssignBlock - 1) / kAssignBlock);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t blk = 0; blk < blocks; ++blk) {
        const std::size_t i0 = static_cast<std::size_t>(blk) * kAssignBlock;
        assign_block(in, i0, std::min(kAssignBlock, n - i0), winner, fmin);
    }
}

double ClusterState::move_centres() {
    const int k = params_.k;
    std::fill(block_sums_.begin(), block_sums_.end(), 0.0);
    const std::size_t n = n_;
#pragma omp parallel for schedule(static)
    for (int blk = 0; blk < kBlocks; ++blk) {
        double* s = block_sums_.data() + static_cast<std::size_t>(blk) * k * kSums;
        const std::size_t i0 = n * blk / kBlocks, i1 = n * (blk + 1) / kBlocks;
        for (std::size_t i = i0; i < i1; ++i) {
            double* sj = s + static_cast<std::size_t>(pts_.winner[i]) * kSums;
            sj[0] += pts_.x[i];
            sj[1] += pts_.y[i];
            sj[2] += pts_.z[i];
            sj[3] += pts_.r[i];
            sj[4] += pts_.g[i];
            sj[5] += pts_.b[i];
            if (pts_.has_normal[i]) {
                sj[6] += pts_.nx[i];
                sj[7] += pts_.ny[i];
                sj[8] += pts_.nz[i];
            }
            sj[9] += 1.0;
            sj[10] += pts_.f[i];
        }
    }
    double total_f = 0;
    for (int j = 0; j < k; ++j) {
        double t[kSums] = {};
        for (int blk = 0; blk < kBlocks; ++blk) {
            const double* sj = block_sums_.data() + (static_cast<std::size_t>(blk) * k + j) * kSums;
            for (int q = 0; q < kSums; ++q) t[q] += sj[q];
        }
        total_f += t[10];
        centres_.count[j] = static_cast<std::int64_t>(t[9]);
        if (t[9] == 0) continue;  // empty: re-seeded by the caller
        const double inv = 1.0 / t[9];
        centres_.x[j] = static_cast<float>(t[0] * inv);
        centres_.y[j] = static_cast<float>(t[1] * inv);
        centres_.z[j] = static_cast<float>(t[2] * inv);
        centres_.r[j] = static_cast<float>(t[3] * inv);
        centres_.g[j] = static_cast<float>(t[4] * inv);
        centres_.b[j] = static_cast<float>(t[5] * inv);
        const double len = std::sqrt(t[6] * t[6] + t[7] * t[7] + t[8] * t[8]);
        const double ninv = len > 1e-12 ? 1.0 / len : 0.0;  // mean normal, renormalized
        centres_.nx[j] = static_cast<float>(t[6] * ninv);
        centres_.ny[j] = static_cast<float>(t[7] * ninv);
        centres_.nz[j] = static_cast<float>(t[8] * ninv);
    }
    return n_ ? total_f / static_cast<double>(n_) : 0.0;
}

int ClusterState::reseed_empty() {
    // A centre that lost all its points moves to a point far from every centre, drawn with
    // k-means++'s D^2 rule, so that a new object entering the scene can take it
    // (ALGORITHM.md, "The loop"; paper Figure 5(b)).
    int reseeded = 0;
    for (int j = 0; j < params_.k; ++j) {
        if (centres_.count[j] != 0 || n_ == 0) continue;
        add_centre(j);
        ++reseeded;
    }
    return reseeded;
}

void ClusterState::update_weights_and_labels() {
    const float psi = params_.psi;
    std::fill(grid_label_.begin(), grid_label_.end(), 0);
    const auto n = static_cast<std::ptrdiff_t>(n_);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < n; ++i) {
        const std::size_t g = static_cast<std::size_t>(pts_.grid[i]);
        const int label = update_weights(mu_[g], pts_.winner[i], psi);
        grid_label_[g] = static_cast<std::uint16_t>(label + 1);
    }
}

void ClusterState::last_winners(std::vector<int>& per_grid_point) const {
    per_grid_point.assign(static_cast<std::size_t>(grid_w_) * grid_h_, -1);
    for (std::size_t i = 0; i < n_; ++i) per_grid_point[pts_.grid[i]] = pts_.winner[i];
}

FrameStats ClusterState::step(const OrganizedCloud& cloud, const NormalMap& normals,
                              const std::vector<std::uint8_t>& active, LabelImage& labels) {
    if (cloud.width != width_ || cloud.height != height_) allocate(cloud.width, cloud.height);
    centre_normal_.resize(params_.k);
    use_color_ = cloud.has_color;
    using Clock = std::chrono::steady_clock;
    auto ms_since = [](Clock::time_point& t) {
        const auto now = Clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - t).count();
        t = now;
        return ms;
    };
    FrameStats stats;
    auto t = Clock::now();
    gather(cloud, normals, active);
    stats.ms.gather = ms_since(t);

    stats.points = n_;
    if (!seeded_) {
        if (n_ < static_cast<std::size_t>(params_.k)) {
            std::ostringstream msg;
            msg << "k = " << params_.k << " is larger than the " << n_
                << " valid points in the depth range of the first frame";
            throw InputError(msg.str());
        }
        seed_kmeanspp();
        seeded_ = true;
        stats.seeded = true;
        stats.ms.seeding = ms_since(t);
    }

    if (n_ > 0) {
        for (int it = 0; it < params_.iters; ++it) {
            assign();
            stats.ms.assign += ms_since(t);
            if (it + 1 == params_.iters) {
                update_weights_and_labels();
                stats.ms.weights = ms_since(t);
            }
            stats.mean_f = move_centres();
            stats.reseeded += reseed_empty();
            stats.ms.centres += ms_since(t);
        }
    } else {
        std::fill(grid_label_.begin(), grid_label_.end(), 0);
    }
    ++tau_;
    stats.tau = tau_;

    // Full-resolution labels: each active pixel takes the label of its grid point.
    const int W = cloud.width, H = cloud.height, s = params_.stride;
    labels.width = W;
    labels.height = H;
    labels.labels.resize(static_cast<std::size_t>(W) * H);
#pragma omp parallel for schedule(static)
    for (int v = 0; v < H; ++v) {
        const std::size_t row = static_cast<std::size_t>(v) * W;
        const std::size_t grow = static_cast<std::size_t>(v / s) * grid_w_;
        if (s == 1) {  // no division per pixel in the common case
            for (int u = 0; u < W; ++u)
                labels.labels[row + u] = active[row + u] ? grid_label_[grow + u] : 0;
        } else {
            for (int u = 0; u < W; ++u)
                labels.labels[row + u] = active[row + u] ? grid_label_[grow + u / s] : 0;
        }
    }
    stats.ms.labels = ms_since(t);
    return stats;
}

}  // namespace wul3d
