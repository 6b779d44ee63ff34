#include "wul3d/clustering.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <tuple>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "branch_free.hpp"
#include "param_check.hpp"
#include "wul3d/error.hpp"
#include "wul3d/stop.hpp"

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

int detail::update_weights_scalar(PixelWeights& w, int winner, float psi) {
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

#if defined(__SSE2__)
namespace {
/// Lanes 0-5 of a 16-bit vector; lanes 6 and 7 are padding.
constexpr int kSlotBytes = (1 << (2 * PixelWeights::kSlots)) - 1;

/// Unsigned 16-bit lanes as signed ones with the same order (SSE2 compares signed only).
inline __m128i flip(__m128i a) { return _mm_xor_si128(a, _mm_set1_epi16(static_cast<short>(0x8000))); }

/// Every lane set to the minimum (max_lanes = false) or maximum of the 8 signed lanes.
inline __m128i spread(__m128i a, bool max_lanes) {
    auto pick = [max_lanes](__m128i x, __m128i y) { return max_lanes ? _mm_max_epi16(x, y) : _mm_min_epi16(x, y); };
    a = pick(a, _mm_shuffle_epi32(a, _MM_SHUFFLE(1, 0, 3, 2)));
    a = pick(a, _mm_shuffle_epi32(a, _MM_SHUFFLE(2, 3, 0, 1)));
    return pick(a, _mm_shufflelo_epi16(_mm_shufflehi_epi16(a, _MM_SHUFFLE(2, 3, 0, 1)),
                                       _MM_SHUFFLE(2, 3, 0, 1)));
}

/// 0-based lane of the first (lowest) set lane of a movemask over 16-bit lanes.
inline int first_lane(int mask) { return __builtin_ctz(static_cast<unsigned>(mask)) / 2; }
}  // namespace

int update_weights(PixelWeights& w, int winner, float psi) {
    // The scalar update (detail::update_weights_scalar) on one pixel's six slots at once,
    // without a data-dependent branch: on a new scene the winner is kept or not at random
    // and the scalar loop's branches mispredict. Same float operations in the same order
    // (sums of 16-bit integers are exact in float), so the result is bit-identical
    // (tests/stages/clustering_test.cpp, PixelWeights.VectorUpdateMatchesScalar).
    constexpr int S = PixelWeights::kSlots;
    static_assert(sizeof(PixelWeights) == 4 * S && S == 6, "24-byte layout: cluster[6], mu[6]");
    if (w.mu[0] == static_cast<std::uint16_t>(PixelWeights::kOne) && w.cluster[0] == winner)
        return winner;  // still scene: see the scalar version
    auto* const bytes = reinterpret_cast<std::uint8_t*>(&w);
    const __m128i zero = _mm_setzero_si128();
    // Bytes 0-15: cluster[0..5], mu[0..1]; bytes 8-23: cluster[4..5], mu[0..5].
    __m128i cluster = _mm_loadu_si128(reinterpret_cast<const __m128i*>(bytes));
    const __m128i mu = _mm_srli_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(bytes + 8)), 4);
    const __m128i lanes = _mm_setr_epi16(0, 1, 2, 3, 4, 5, 6, 7);

    const __m128i kept = _mm_andnot_si128(_mm_cmpeq_epi16(mu, zero),
                                          _mm_cmpeq_epi16(cluster, _mm_set1_epi16(static_cast<short>(winner))));
    const int kept_mask = _mm_movemask_epi8(kept) & kSlotBytes;
    int slot;
    __m128i mu_in = mu;  // the weights before psi, with the dropped one zeroed
    if (kept_mask) {
        slot = (31 - __builtin_clz(static_cast<unsigned>(kept_mask))) / 2;  // the last, as the scalar loop
    } else {
        // The smallest slot (the first of equals) takes the winner; padding lanes never win.
        const __m128i padded = flip(_mm_or_si128(mu, _mm_setr_epi16(0, 0, 0, 0, 0, 0, -1, -1)));
        slot = first_lane(_mm_movemask_epi8(_mm_cmpeq_epi16(padded, spread(padded, false))));
        const __m128i at_slot = _mm_cmpeq_epi16(lanes, _mm_set1_epi16(static_cast<short>(slot)));
        cluster = _mm_or_si128(_mm_andnot_si128(at_slot, cluster),
                               _mm_and_si128(at_slot, _mm_set1_epi16(static_cast<short>(winner))));
        mu_in = _mm_andnot_si128(at_slot, mu);
    }
    // Paper eq. (2), then (7)-(8) on the kept weights, in units of kOne (as the scalar one).
    const __m128i lo32 = _mm_unpacklo_epi16(mu_in, zero), hi32 = _mm_unpackhi_epi16(mu_in, zero);
    __m128i isum = _mm_add_epi32(lo32, hi32);
    isum = _mm_add_epi32(isum, _mm_shuffle_epi32(isum, _MM_SHUFFLE(1, 0, 3, 2)));
    isum = _mm_add_epi32(isum, _mm_shuffle_epi32(isum, _MM_SHUFFLE(2, 3, 0, 1)));
    const float psi_one = psi * PixelWeights::kOne;
    const float sum = static_cast<float>(_mm_cvtsi128_si32(isum));
    const __m128 scale = _mm_set1_ps(PixelWeights::kOne / (sum + psi_one));
    const __m128i slot32 = _mm_set1_epi32(slot);
    const __m128 add_lo = _mm_and_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_setr_epi32(0, 1, 2, 3), slot32)), _mm_set1_ps(psi_one));
    const __m128 add_hi = _mm_and_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_setr_epi32(4, 5, 6, 7), slot32)), _mm_set1_ps(psi_one));
    const __m128 one = _mm_set1_ps(PixelWeights::kOne), half = _mm_set1_ps(0.5f);
    auto normalize = [&](__m128i m32, __m128 add) {
        const __m128 m = _mm_add_ps(_mm_cvtepi32_ps(m32), add);
        // Truncation after + 0.5, then re-centred so that the signed pack keeps 0..65535.
        return _mm_sub_epi32(_mm_cvttps_epi32(_mm_min_ps(one, _mm_add_ps(_mm_mul_ps(m, scale), half))),
                             _mm_set1_epi32(32768));
    };
    const __m128i out = flip(_mm_packs_epi32(normalize(lo32, add_lo), normalize(hi32, add_hi)));
    // Store cluster[0..3], then cluster[4..5] with mu[0..5]: exactly the struct's 24 bytes.
    _mm_storel_epi64(reinterpret_cast<__m128i*>(bytes), cluster);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(bytes + 8),
                     _mm_or_si128(_mm_srli_si128(_mm_slli_si128(cluster, 4), 12), _mm_slli_si128(out, 4)));
    // Arg-max, ties to the winner's slot; else the first of the largest (as the scalar loop).
    const __m128i signed_out = flip(out);  // padding lanes are 0, below every kept weight
    const __m128i largest = spread(signed_out, true);
    int best = slot;
    if (w.mu[slot] != static_cast<std::uint16_t>(_mm_extract_epi16(flip(largest), 0)))
        best = first_lane(_mm_movemask_epi8(_mm_cmpeq_epi16(signed_out, largest)) & kSlotBytes);
    const std::uint16_t label = w.cluster[best];
    if (w.mu[best] == static_cast<std::uint16_t>(PixelWeights::kOne) && best != 0) {
        std::swap(w.cluster[0], w.cluster[best]);  // keeps the fast path above reachable
        std::swap(w.mu[0], w.mu[best]);
    }
    return label;
}
#else
int update_weights(PixelWeights& w, int winner, float psi) {
    return detail::update_weights_scalar(w, winner, psi);
}
#endif

// ---- ClusterState -----------------------------------------------------------------------

namespace {
// Grid points are taken in blocks of kAssignBlock, read in place from the cloud or gathered
// into a small buffer on the stack (nothing grid-sized is copied), and the blocks are split
// into kChunks fixed ranges for the sums. Sums are reduced in chunk order, so
// results do not depend on the number of threads.
constexpr std::size_t kAssignBlock = 256;
constexpr int kChunks = 64;
/// The greedy k-means++ draws' candidates per centre: 2 + ln k, k <= 65535.
constexpr int kMaxTrials = 13;
constexpr int kSums = 11;  // x y z r g b nx ny nz, count, f
constexpr std::uint16_t kNoWinner = 0xffff;  // k <= 65535, so 0-based winners stay below it

/// The active grid points of one block gathered, structure of arrays (on the stack).
struct PointBlock {
    std::uint32_t grid[kAssignBlock];
    float x[kAssignBlock], y[kAssignBlock], z[kAssignBlock];
    std::uint8_t r[kAssignBlock], g[kAssignBlock], b[kAssignBlock];
    float nx[kAssignBlock], ny[kAssignBlock], nz[kAssignBlock];
    std::uint8_t has_normal[kAssignBlock];
};

/// The points of one block as the kernel reads them: m points, either gathered into a
/// PointBlock (grid = their grid indices) or, for a block of the full-resolution grid, the
/// cloud's own arrays from pixel g0 on (grid = null; see Grid::points).
struct PointView {
    const float *x, *y, *z;
    const std::uint8_t *r, *g, *b;
    const float *nx, *ny, *nz;
    const std::uint8_t* has_normal;
    const std::uint32_t* grid;
    std::size_t g0, m;
    std::size_t index(std::size_t q) const { return grid ? grid[q] : g0 + q; }
};

/// What the assignment kernel compares the points with: centres, structure of arrays.
struct CentreView {
    const float *x, *y, *z, *r, *g, *b, *nx, *ny, *nz;
    const float* has_normal;  ///< 1 or 0 per centre
    int k;
    float d2, a2, gamma;      ///< delta^2, alpha^2 (0 without colour), gamma
};

/// Winner and f of each point of the block. Points in the inner loop, centres in the outer
/// (as FAISS does): the inner loop runs over contiguous points and vectorizes whatever k
/// is. Built twice, for AVX2 and for baseline x86-64, picked at load time: baseline SSE2 has
/// no blend, so GCC keeps the arg-min scalar there.
WUL3D_AVX2_CLONES
void assign_block(const CentreView& c, const PointView& pb, int* winner, float* fmin) {
    const std::size_t m = pb.m;
    // Colours and the normal flag as floats first: with 8-bit loads in it, GCC does not
    // vectorize the loop over the centres.
    float R[kAssignBlock], G[kAssignBlock], B[kAssignBlock];
    float gamma[kAssignBlock];  // gamma where the point has a normal, else 0 (eq. 6 needs both)
    for (std::size_t q = 0; q < m; ++q) {
        R[q] = pb.r[q];
        G[q] = pb.g[q];
        B[q] = pb.b[q];
        gamma[q] = static_cast<float>(pb.has_normal[q] != 0) * c.gamma;
        fmin[q] = INFINITY;
        winner[q] = 0;
    }
    for (int j = 0; j < c.k; ++j) {
        const float qx = c.x[j], qy = c.y[j], qz = c.z[j];
        const float qr = c.r[j], qg = c.g[j], qb = c.b[j];
        const float qnx = c.nx[j], qny = c.ny[j], qnz = c.nz[j];
        const float qn = c.has_normal[j];
        for (std::size_t q = 0; q < m; ++q) {
            const float dx = pb.x[q] - qx, dy = pb.y[q] - qy, dz = pb.z[q] - qz;
            const float dr = R[q] - qr, dg = G[q] - qg, db = B[q] - qb;
            // Eq. (4); the square root stays: with eq. (6)'s additive normal term the
            // arg-min of f is not the arg-min of the squared distance.
            const float dist = std::sqrt(c.d2 * (dx * dx + dy * dy + dz * dz) +
                                         c.a2 * (dr * dr + dg * dg + db * db));
            const float cos_theta = pb.nx[q] * qnx + pb.ny[q] * qny + pb.nz[q] * qnz;
            const float f = dist + gamma[q] * qn * (1.0f - cos_theta);  // eq. (6)
            const bool better = f < fmin[q];
            fmin[q] = better ? f : fmin[q];
            winner[q] = better ? j : winner[q];
        }
    }
}
}  // namespace

/// The frame as the clustering sees it: the sampled grid over the cloud, normals and mask.
struct ClusterState::Grid {
    const OrganizedCloud& cloud;
    const NormalMap& normals;
    const std::uint8_t* active;
    int stride, w, h;

    std::size_t size() const { return static_cast<std::size_t>(w) * h; }
    std::size_t blocks() const { return (size() + kAssignBlock - 1) / kAssignBlock; }
    /// Full-resolution pixel of grid point g.
    std::size_t pixel(std::size_t g) const {
        const std::size_t gv = g / static_cast<std::size_t>(w), gu = g % static_cast<std::size_t>(w);
        return (gv * static_cast<std::size_t>(cloud.width) + gu) * static_cast<std::size_t>(stride);
    }
    /// Grid points of the blocks of chunk c: [first, last).
    std::pair<std::size_t, std::size_t> chunk(int c) const {
        const std::size_t n = blocks();
        return {std::min(size(), n * c / kChunks * kAssignBlock),
                std::min(size(), n * (c + 1) / kChunks * kAssignBlock)};
    }
    /// The active points among grid points [g0, g1), g1 - g0 <= kAssignBlock: the cloud's
    /// own arrays when the grid is the full resolution and all of them are active (most
    /// blocks), else gathered into pb. With `or_all`, a full-resolution block comes whole,
    /// inactive points included, for a caller that masks them itself (no gather at all).
    PointView points(std::size_t g0, std::size_t g1, PointBlock& pb, bool or_all = false) const {
        if (stride == 1) {
            std::size_t n_active = 0;
            if (!or_all)
                for (std::size_t g = g0; g < g1; ++g) n_active += active[g];
            if (or_all || n_active == g1 - g0)
                return {cloud.x.data() + g0,   cloud.y.data() + g0,   cloud.z.data() + g0,
                        cloud.r.data() + g0,   cloud.g.data() + g0,   cloud.b.data() + g0,
                        normals.nx.data() + g0, normals.ny.data() + g0, normals.nz.data() + g0,
                        normals.valid.data() + g0, nullptr, g0, g1 - g0};
        }
        // Raw pointers: the byte stores below may alias anything, so through the vectors
        // the compiler would reload every data pointer on each point.
        const float *const X = cloud.x.data(), *const Y = cloud.y.data(), *const Z = cloud.z.data();
        const std::uint8_t *const R = cloud.r.data(), *const G = cloud.g.data(),
                           *const B = cloud.b.data(), *const valid = normals.valid.data();
        const float *const NX = normals.nx.data(), *const NY = normals.ny.data(),
                    *const NZ = normals.nz.data();
        std::size_t m = 0;
        const std::size_t W = static_cast<std::size_t>(cloud.width), s = static_cast<std::size_t>(stride);
        std::size_t gv = g0 / static_cast<std::size_t>(w), gu = g0 % static_cast<std::size_t>(w);
        for (std::size_t g = g0; g < g1; ++g) {
            const std::size_t p = (gv * W + gu) * s;
            if (active[p]) {
                pb.grid[m] = static_cast<std::uint32_t>(g);
                pb.x[m] = X[p];
                pb.y[m] = Y[p];
                pb.z[m] = Z[p];
                pb.r[m] = R[p];
                pb.g[m] = G[p];
                pb.b[m] = B[p];
                pb.nx[m] = NX[p];  // 0 where there is no normal (normals.hpp)
                pb.ny[m] = NY[p];
                pb.nz[m] = NZ[p];
                pb.has_normal[m] = valid[p];
                ++m;
            }
            if (++gu == static_cast<std::size_t>(w)) {
                gu = 0;
                ++gv;
            }
        }
        return {pb.x, pb.y, pb.z, pb.r, pb.g, pb.b, pb.nx, pb.ny, pb.nz, pb.has_normal, pb.grid, g0, m};
    }
};

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

namespace {
/// `v` resized to `n` zeros, 8 MB at a time with a stop check between: at k = 65535 the
/// centre sums are 369 MB, whose one memset takes seconds on a loaded machine.
void zero_checked(std::vector<double>& v, std::size_t n) {
    constexpr std::size_t kSlice = std::size_t{1} << 20;
    if (v.size() > n) v.resize(n);
    for (std::size_t i = 0; i < v.size(); i += kSlice) {
        std::fill(v.begin() + static_cast<std::ptrdiff_t>(i),
                  v.begin() + static_cast<std::ptrdiff_t>(std::min(v.size(), i + kSlice)), 0.0);
        throw_if_stop_requested("the clustering's allocation");
    }
    v.reserve(n);
    while (v.size() < n) {
        v.resize(std::min(n, v.size() + kSlice), 0.0);
        throw_if_stop_requested("the clustering's allocation");
    }
}
}  // namespace

void ClusterState::allocate(int width, int height) {
    width_ = width;
    height_ = height;
    const int s = params_.stride;
    grid_w_ = (width + s - 1) / s;
    grid_h_ = (height + s - 1) / s;
    const std::size_t grid = static_cast<std::size_t>(grid_w_) * grid_h_;
    mu_.assign(grid, PixelWeights{});
    grid_label_.assign(grid, 0);
    winner_.assign(grid, kNoWinner);
    f_.assign(grid, 0.0f);
    zero_checked(chunk_sums_, static_cast<std::size_t>(kChunks) * params_.k * kSums);
    reset();
}

std::size_t ClusterState::count_active(const Grid& grid) const {
    std::size_t n = 0;
#pragma omp parallel for schedule(static) reduction(+ : n)
    for (int gv = 0; gv < grid.h; ++gv) {
        const std::uint8_t* row = grid.active + grid.pixel(static_cast<std::size_t>(gv) * grid.w);
        for (int gu = 0; gu < grid.w; ++gu) n += row[static_cast<std::size_t>(gu) * grid.stride];
    }
    return n;
}

std::size_t ClusterState::nth_active(const Grid& grid, std::size_t r) const {
    for (std::size_t g = 0, gv = 0; gv < static_cast<std::size_t>(grid.h); ++gv) {
        const std::uint8_t* row = grid.active + grid.pixel(gv * grid.w);
        for (int gu = 0; gu < grid.w; ++gu, ++g)
            if (row[static_cast<std::size_t>(gu) * grid.stride] && r-- == 0) return g;
    }
    return 0;  // not reached: r < n_
}

void ClusterState::set_centre(int j, const Grid& grid, std::size_t g) {
    const std::size_t p = grid.pixel(g);
    centres_.x[j] = grid.cloud.x[p];
    centres_.y[j] = grid.cloud.y[p];
    centres_.z[j] = grid.cloud.z[p];
    centres_.r[j] = grid.cloud.r[p];
    centres_.g[j] = grid.cloud.g[p];
    centres_.b[j] = grid.cloud.b[p];
    centres_.nx[j] = grid.normals.nx[p];
    centres_.ny[j] = grid.normals.ny[p];
    centres_.nz[j] = grid.normals.nz[p];
    centres_.count[j] = 0;
}

namespace {
/// The candidates' features, one CentreView of one centre each: what assign_block compares
/// the points with.
struct Candidates {
    float x[kMaxTrials], y[kMaxTrials], z[kMaxTrials], r[kMaxTrials], g[kMaxTrials], b[kMaxTrials];
    float nx[kMaxTrials], ny[kMaxTrials], nz[kMaxTrials], has_normal[kMaxTrials];
    CentreView view[kMaxTrials];
};
}  // namespace

void ClusterState::f_to_points(const Grid& grid, const std::size_t* c, int n, FToPoint use, double* potential) {
    // Points c[t] as the one centre of the assignment kernel each, all in one pass, so that
    // the potentials' sums run side by side (below).
    Candidates cand;
    for (int t = 0; t < n; ++t) {
        const std::size_t pc = grid.pixel(c[t]);
        cand.x[t] = grid.cloud.x[pc], cand.y[t] = grid.cloud.y[pc], cand.z[t] = grid.cloud.z[pc];
        cand.r[t] = grid.cloud.r[pc], cand.g[t] = grid.cloud.g[pc], cand.b[t] = grid.cloud.b[pc];  // 0-255
        cand.nx[t] = grid.normals.nx[pc], cand.ny[t] = grid.normals.ny[pc], cand.nz[t] = grid.normals.nz[pc];
        cand.has_normal[t] = grid.normals.valid[pc] ? 1.0f : 0.0f;
        cand.view[t] = CentreView{&cand.x[t],  &cand.y[t],  &cand.z[t],  &cand.r[t],
                                  &cand.g[t],  &cand.b[t],  &cand.nx[t], &cand.ny[t],
                                  &cand.nz[t], &cand.has_normal[t], 1,
                                  params_.delta * params_.delta,
                                  use_color_ ? params_.alpha * params_.alpha : 0.0f, params_.gamma};
    }
    double chunk_potential[kChunks][kMaxTrials] = {};
#pragma omp parallel for schedule(static)
    for (int ch = 0; ch < kChunks; ++ch) {
        PointBlock pb;
        int winner[kAssignBlock];
        float f[kMaxTrials][kAssignBlock];
        double sums[kMaxTrials] = {};
        const auto [first, last] = grid.chunk(ch);
        for (std::size_t g0 = first; g0 < last; g0 += kAssignBlock) {
            if (stop_requested()) break;  // thrown below, outside the parallel region
            const std::size_t g1 = std::min(last, g0 + kAssignBlock);
            // Inactive points may come along: f_ is 0 there, which Lower and Potential
            // keep (f >= 0) and Set writes.
            const PointView pts = grid.points(g0, g1, pb, /*or_all=*/true);
            for (int t = 0; t < n; ++t) assign_block(cand.view[t], pts, winner, f[t]);
            if (use == FToPoint::Set) {
                std::fill(f_.begin() + static_cast<std::ptrdiff_t>(g0),
                          f_.begin() + static_cast<std::ptrdiff_t>(g1), 0.0f);
                for (std::size_t q = 0; q < pts.m; ++q)
                    if (grid.active[grid.pixel(pts.index(q))]) f_[pts.index(q)] = f[0][q];
            } else if (use == FToPoint::Lower) {
                for (std::size_t q = 0; q < pts.m; ++q)
                    f_[pts.index(q)] = std::min(f_[pts.index(q)], f[0][q]);
            } else {
                // Each sum in point order (a double sum in another order would round
                // otherwise), the candidates' sums side by side: their chains of additions
                // overlap, where one after the other each waits on its last addition.
                for (std::size_t q = 0; q < pts.m; ++q) {
                    const float fq = f_[pts.index(q)];
                    for (int t = 0; t < n; ++t) {
                        const double d = std::min(fq, f[t][q]);
                        sums[t] += d * d;
                    }
                }
            }
        }
        for (int t = 0; t < n; ++t) chunk_potential[ch][t] = sums[t];
    }
    throw_if_stop_requested("the clustering's seeding");
    if (use != FToPoint::Potential) return;
    for (int t = 0; t < n; ++t) {
        double total = 0;
        for (int ch = 0; ch < kChunks; ++ch) total += chunk_potential[ch][t];
        potential[t] = total;
    }
}

std::size_t ClusterState::sample_by_f_squared(const Grid& grid) {
    // Greedy k-means++ (Arthur & Vassilvitskii 2007, section 6): draw a few candidates with
    // probability proportional to f^2, f being the distance to the nearest centre chosen so
    // far, and keep the one that lowers the total f^2 most. Sums run in fixed chunks, in
    // order, so the choice does not depend on the thread count.
    double chunk_total[kChunks];
    // Each chunk's sum in its points' order, kSideBySide chunks' side by side: their chains
    // of additions overlap, where one after the other each waits on its last addition.
    constexpr int kSideBySide = 4;
    static_assert(kChunks % kSideBySide == 0);
    const float* const f = f_.data();
#pragma omp parallel for schedule(static)
    for (int group = 0; group < kChunks / kSideBySide; ++group) {
        std::size_t first[kSideBySide], last[kSideBySide], common = SIZE_MAX;
        double sum[kSideBySide] = {};
        for (int i = 0; i < kSideBySide; ++i) {
            std::tie(first[i], last[i]) = grid.chunk(group * kSideBySide + i);
            common = std::min(common, last[i] - first[i]);
        }
        for (std::size_t j = 0; j < common; ++j)
            for (int i = 0; i < kSideBySide; ++i) {
                const double v = f[first[i] + j];
                sum[i] += v * v;
            }
        for (int i = 0; i < kSideBySide; ++i) {
            for (std::size_t g = first[i] + common; g < last[i]; ++g) sum[i] += static_cast<double>(f[g]) * f[g];
            chunk_total[group * kSideBySide + i] = sum[i];
        }
    }
    double total = 0;
    for (double t : chunk_total) total += t;
    // At most kMaxTrials: k <= 65535 (ClusterParams).
    const int trials = std::min(kMaxTrials, 2 + static_cast<int>(std::log(static_cast<double>(params_.k))));
    // The draws do not depend on the potentials: all are drawn first (the generator's
    // numbers in the same order), then measured in one pass.
    std::size_t candidate[kMaxTrials];
    for (int t = 0; t < trials; ++t) {
        std::size_t c = 0;
        if (total > 0) {
            // The first point whose running sum of f^2 passes the target: find its chunk,
            // then walk the chunk. Points outside the mask have f = 0 and are never drawn.
            const double target = std::uniform_real_distribution<double>(0.0, total)(rng_);
            double acc = 0;
            int ch = 0;
            while (ch + 1 < kChunks && acc + chunk_total[ch] <= target) acc += chunk_total[ch++];
            const auto [first, last] = grid.chunk(ch);
            c = last;
            std::size_t last_drawable = first;
            for (std::size_t g = first; g < last; ++g) {
                if (f_[g] == 0) continue;
                last_drawable = g;
                acc += static_cast<double>(f_[g]) * f_[g];
                if (acc > target) {
                    c = g;
                    break;
                }
            }
            if (c == last) c = last_drawable;  // rounding put the target past the chunk's end
        } else {  // every point sits on a centre: any point will do
            c = nth_active(grid, std::uniform_int_distribution<std::size_t>(0, n_ - 1)(rng_));
        }
        candidate[t] = c;
    }
    double potential[kMaxTrials];
    f_to_points(grid, candidate, trials, FToPoint::Potential, potential);
    std::size_t best = 0;
    double best_potential = INFINITY;
    for (int t = 0; t < trials; ++t)
        if (potential[t] < best_potential) {
            best_potential = potential[t];
            best = candidate[t];
        }
    return best;
}

void ClusterState::add_centre(int j, const Grid& grid) {
    const std::size_t c = sample_by_f_squared(grid);
    set_centre(j, grid, c);
    f_to_points(grid, &c, 1, FToPoint::Lower, nullptr);
}

void ClusterState::seed_kmeanspp(const Grid& grid) {
    const std::size_t first =
        nth_active(grid, std::uniform_int_distribution<std::size_t>(0, n_ - 1)(rng_));
    set_centre(0, grid, first);
    f_to_points(grid, &first, 1, FToPoint::Set, nullptr);
    for (int j = 1; j < params_.k; ++j) {
        throw_if_stop_requested("the clustering's seeding");
        add_centre(j, grid);
    }
}

void ClusterState::assign(const Grid& grid) {
    const int k = params_.k;
    // 1 where the centre has a normal, so that the normal term drops out for it (eq. 6
    // needs both normals).
    for (int j = 0; j < k; ++j) centre_normal_[j] = centre_has_normal(j) ? 1.0f : 0.0f;
    const CentreView view{centres_.x.data(),  centres_.y.data(),  centres_.z.data(),
                          centres_.r.data(),  centres_.g.data(),  centres_.b.data(),
                          centres_.nx.data(), centres_.ny.data(), centres_.nz.data(),
                          centre_normal_.data(), k, params_.delta * params_.delta,
                          use_color_ ? params_.alpha * params_.alpha : 0.0f, params_.gamma};
    zero_checked(chunk_sums_, chunk_sums_.size());
#pragma omp parallel for schedule(static)
    for (int ch = 0; ch < kChunks; ++ch) {
        PointBlock pb;
        int winner[kAssignBlock];
        float f[kAssignBlock];
        double* sums = chunk_sums_.data() + static_cast<std::size_t>(ch) * k * kSums;
        const auto [first, last] = grid.chunk(ch);
        for (std::size_t g0 = first; g0 < last; g0 += kAssignBlock) {
            // A block is 256 points against every centre: long enough at the largest k to be
            // worth a look for a stop request.
            if (stop_requested()) break;  // thrown below, outside the parallel region
            const std::size_t g1 = std::min(last, g0 + kAssignBlock);
            const PointView pts = grid.points(g0, g1, pb);
            assign_block(view, pts, winner, f);
            std::fill(winner_.begin() + static_cast<std::ptrdiff_t>(g0),
                      winner_.begin() + static_cast<std::ptrdiff_t>(g1), kNoWinner);
            std::fill(f_.begin() + static_cast<std::ptrdiff_t>(g0),
                      f_.begin() + static_cast<std::ptrdiff_t>(g1), 0.0f);
            // The centre sums of move_centres, while the block is in cache. A point without
            // a normal has a zero normal (normals.hpp), so it adds nothing to the normal sums.
            for (std::size_t q = 0; q < pts.m; ++q) {
                winner_[pts.index(q)] = static_cast<std::uint16_t>(winner[q]);
                f_[pts.index(q)] = f[q];
                double* sj = sums + static_cast<std::size_t>(winner[q]) * kSums;
                sj[0] += pts.x[q];
                sj[1] += pts.y[q];
                sj[2] += pts.z[q];
                sj[3] += pts.r[q];
                sj[4] += pts.g[q];
                sj[5] += pts.b[q];
                sj[6] += pts.nx[q];
                sj[7] += pts.ny[q];
                sj[8] += pts.nz[q];
                sj[9] += 1.0;
                sj[10] += f[q];
            }
        }
    }
    throw_if_stop_requested("the clustering");
}

double ClusterState::move_centres() {
    const int k = params_.k;
    double total_f = 0;
    for (int j = 0; j < k; ++j) {
        double t[kSums] = {};
        for (int ch = 0; ch < kChunks; ++ch) {
            const double* sj = chunk_sums_.data() + (static_cast<std::size_t>(ch) * k + j) * kSums;
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

int ClusterState::reseed_empty(const Grid& grid) {
    // A centre that lost all its points moves to a point far from every centre, drawn with
    // k-means++'s D^2 rule, so that a new object entering the scene can take it
    // (ALGORITHM.md, "The loop"; paper Figure 5(b)).
    int reseeded = 0;
    for (int j = 0; j < params_.k; ++j) {
        if (centres_.count[j] != 0 || n_ == 0) continue;
        throw_if_stop_requested("the clustering's re-seeding");
        add_centre(j, grid);
        ++reseeded;
    }
    return reseeded;
}

void ClusterState::update_weights_and_labels() {
    const float psi = params_.psi;
    const auto size = static_cast<std::ptrdiff_t>(winner_.size());
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t g = 0; g < size; ++g) {
        const std::uint16_t w = winner_[g];
        grid_label_[g] = w == kNoWinner
                             ? std::uint16_t{0}
                             : static_cast<std::uint16_t>(update_weights(mu_[g], w, psi) + 1);
    }
}

void ClusterState::last_winners(std::vector<int>& per_grid_point) const {
    per_grid_point.resize(winner_.size());
    for (std::size_t g = 0; g < winner_.size(); ++g)
        per_grid_point[g] = winner_[g] == kNoWinner ? -1 : winner_[g];
}

FrameStats ClusterState::step(const OrganizedCloud& cloud, const NormalMap& normals,
                              const std::vector<std::uint8_t>& active, LabelImage& labels) {
    if (cloud.width != width_ || cloud.height != height_) allocate(cloud.width, cloud.height);
    centre_normal_.resize(params_.k);
    use_color_ = cloud.has_color;
    const Grid grid{cloud, normals, active.data(), params_.stride, grid_w_, grid_h_};
    using Clock = std::chrono::steady_clock;
    auto ms_since = [](Clock::time_point& t) {
        const auto now = Clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - t).count();
        t = now;
        return ms;
    };
    FrameStats stats;
    auto t = Clock::now();
    n_ = count_active(grid);
    stats.points = n_;
    if (!seeded_) {
        if (n_ < static_cast<std::size_t>(params_.k)) {
            std::ostringstream msg;
            msg << "k = " << params_.k << " is larger than the " << n_
                << " valid points in the depth range of the first frame";
            throw InputError(msg.str());
        }
        seed_kmeanspp(grid);
        seeded_ = true;
        stats.seeded = true;
    }
    stats.ms.seeding = ms_since(t);  // with the count of active points

    for (int it = 0; it < params_.iters && n_ > 0; ++it) {
        assign(grid);
        stats.ms.assign += ms_since(t);
        if (it + 1 == params_.iters) {
            update_weights_and_labels();
            stats.ms.weights = ms_since(t);
        }
        stats.mean_f = move_centres();
        stats.reseeded += reseed_empty(grid);
        stats.ms.centres += ms_since(t);
    }
    if (n_ == 0) {  // nothing to cluster: weights and centres stay as they were
        std::fill(winner_.begin(), winner_.end(), kNoWinner);
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
