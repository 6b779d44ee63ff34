#pragma once
/// @file weights.hpp
/// The paper's per-pixel membership weights mu (eq. 2, 7, 8), shared by the clusters
/// (ClusterState, clustering.hpp: one weight per cluster) and the object tracks
/// (ObjectTracker, objects.hpp: one per track slot). Defined in src/stages/clustering.cpp, where
/// the clusters' per-pixel loop inlines the update.
#include <cstdint>

namespace wul3d {

/// One weight update of eq. (2), (7), (8), read as ALGORITHM.md step 7: add psi to the
/// winner, then L1-normalize. With weights already normalized this is
/// mu <- (mu + psi e_winner) / (1 + psi); all-zero weights (a pixel never seen) become
/// e_winner. Returns the arg-max of the new weights; ties go to the winner, the newest
/// evidence.
int update_weights(float* mu, int k, int winner, float psi);

/// The weights of one pixel that matter: its kSlots largest weights mu (eq. 7, 8), with their
/// 0-based cluster ids, in 16-bit fixed point (1 = kOne); an unused slot has weight 0, and
/// all-zero means "never seen". Keeping these instead of all k bounds memory independently
/// of k: 24 bytes a pixel, where dense float weights at 1920x1080 and k = 100 would take
/// 830 MB. A weight is dropped only when a seventh cluster wins while six are kept; it is
/// then the smallest (with psi = 1 at most 1/64 after six other winners). Labels and eq. (9)
/// colours match dense float weights on real sequences (tests/stages/clustering_test.cpp). Six
/// slots, not eight, is what brings 1920x1080 under the speed issue's 160 MB floor; labels
/// on osd_mosd and osd_moving came out identical to eight.
struct PixelWeights {
    static constexpr int kSlots = 6;
    static constexpr float kOne = 65535.0f;
    std::uint16_t cluster[kSlots] = {};
    std::uint16_t mu[kSlots] = {};

    /// mu of cluster j (0-based), in [0, 1]: its weight if kept, else 0.
    float weight(int j) const {
        for (int s = 0; s < kSlots; ++s)
            if (mu[s] > 0 && cluster[s] == j) return static_cast<float>(mu[s]) / kOne;
        return 0.0f;
    }
};

/// update_weights on the kept weights: psi is added to the winner (which takes the slot of
/// the smallest kept weight if it is not kept: that weight is dropped), then the kept
/// weights are L1-normalized. Returns the 0-based arg-max cluster; ties go to the winner.
int update_weights(PixelWeights& w, int winner, float psi);

namespace detail {
/// The same update, one slot at a time: the reference the SSE2 update_weights above is tested
/// against bit for bit, and the update itself where SSE2 is missing.
int update_weights_scalar(PixelWeights& w, int winner, float psi);
}  // namespace detail

}  // namespace wul3d
