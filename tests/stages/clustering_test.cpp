#include "wul3d/clustering.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <random>
#include <set>

#include "synthetic_scene.hpp"
#include "test_support.hpp"
#include "wul3d/io.hpp"
#include "wul3d/visualization.hpp"
#include "wul3d/background.hpp"
#include "wul3d/error.hpp"
#include "wul3d/normals.hpp"

using namespace wul3d;
using namespace wul3d::test;

// ---- parameters -------------------------------------------------------------------------

TEST(ClusterParams, PaperPresetIsTheAuthorsValues) {
    const ClusterParams p = ClusterParams::paper();
    EXPECT_FLOAT_EQ(p.alpha, 0.0033f);
    EXPECT_FLOAT_EQ(p.delta, 1.0f - 0.0033f);
    EXPECT_FLOAT_EQ(p.gamma, 0.0001f);
    EXPECT_FLOAT_EQ(p.psi, 1.0f);
    EXPECT_NO_THROW(p.validate());
}

TEST(ClusterParams, ValidateRejectsOutOfRange) {
    auto bad = [](auto edit) {
        ClusterParams p;
        edit(p);
        EXPECT_THROW(p.validate(), ParamError);
    };
    bad([](ClusterParams& p) { p.k = 0; });
    bad([](ClusterParams& p) { p.alpha = 0.001f; });
    bad([](ClusterParams& p) { p.alpha = 0.5f; });
    bad([](ClusterParams& p) { p.alpha = NAN; });
    bad([](ClusterParams& p) { p.delta = 0.0f; });
    bad([](ClusterParams& p) { p.alpha = 0.05f; p.delta = 0.96f; });  // eq. (5)
    bad([](ClusterParams& p) { p.gamma = 0.0f; });
    bad([](ClusterParams& p) { p.gamma = 0.1f; });
    bad([](ClusterParams& p) { p.psi = 0.0f; });
    bad([](ClusterParams& p) { p.psi = 1.5f; });
    bad([](ClusterParams& p) { p.iters = 0; });
    bad([](ClusterParams& p) { p.stride = 0; });
    try {
        ClusterParams p;
        p.alpha = 0.5f;
        p.validate();
    } catch (const ParamError& e) {
        EXPECT_NE(std::string(e.what()).find("alpha = 0.5"), std::string::npos) << e.what();
    }
}

// ---- eq. (4) and (6) by hand ------------------------------------------------------------

TEST(DistanceF, MatchesEquations4And6ByHand) {
    ClusterParams p;
    p.alpha = 0.01f;
    p.delta = 0.9f;
    p.gamma = 0.005f;
    // position difference (0.3, 0, 0.4) -> 0.5 m; colour difference (30, 40, 0) -> 50
    // dist = sqrt(0.81 * 0.25 + 0.0001 * 2500) = sqrt(0.2025 + 0.25) = sqrt(0.4525)
    const double cos_theta = std::cos(M_PI / 3);  // 60 degrees: 1 - cos = 0.5
    const double f = distance_f(p, 1.3f, 2.0f, 1.4f, 130, 40, 7, 1.0f, 2.0f, 1.0f, 100, 0, 7,
                                cos_theta, true);
    EXPECT_NEAR(f, std::sqrt(0.4525) + 0.005 * 0.5, 1e-6);
    // Without normals the normal term drops out; without colour the colour term does.
    EXPECT_NEAR(distance_f(p, 1.3f, 2.0f, 1.4f, 130, 40, 7, 1.0f, 2.0f, 1.0f, 100, 0, 7,
                           cos_theta, false),
                std::sqrt(0.4525), 1e-6);
    EXPECT_NEAR(distance_f(p, 1.3f, 2.0f, 1.4f, 130, 40, 7, 1.0f, 2.0f, 1.0f, 100, 0, 7,
                           cos_theta, false, false),
                0.9 * 0.5, 1e-6);
    // f = 0 only for identical point and centre
    EXPECT_DOUBLE_EQ(distance_f(p, 1, 2, 3, 4, 5, 6, 1, 2, 3, 4, 5, 6, 1.0, true), 0.0);
}

TEST(DistanceF, PaperUnitsPutColourAndPositionOnOneScale) {
    // ALGORITHM.md step 6: with the paper's preset a colour difference of 30 weighs about
    // as much as 10 cm.
    const ClusterParams p = ClusterParams::paper();
    const double colour = distance_f(p, 0, 0, 1, 30, 0, 0, 0, 0, 1, 0, 0, 0, 1, false);
    const double position = distance_f(p, 0.1f, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, false);
    EXPECT_NEAR(colour / position, 1.0, 0.02);
}

// ---- the weight update, eq. (2), (7), (8) -------------------------------------------------

TEST(UpdateWeights, KeepsSumOneAndHalvesWithPsiOne) {
    std::vector<float> mu(5, 0.0f);
    EXPECT_EQ(update_weights(mu.data(), 5, 2, 1.0f), 2);  // never seen: all on the winner
    EXPECT_FLOAT_EQ(mu[2], 1.0f);
    for (int frame = 0; frame < 20; ++frame) {
        const int winner = (frame * 3) % 5;
        const int label = update_weights(mu.data(), 5, winner, 1.0f);
        EXPECT_NEAR(std::accumulate(mu.begin(), mu.end(), 0.0), 1.0, 1e-5);
        EXPECT_GE(mu[winner], 0.5f);  // psi = 1: the new winner holds at least half
        EXPECT_EQ(label, winner);
    }
}

TEST(UpdateWeights, IsAnExponentialAverageWithRatePsiOverOnePlusPsi) {
    std::vector<float> mu = {0.7f, 0.2f, 0.1f};
    const int label = update_weights(mu.data(), 3, 1, 0.25f);
    EXPECT_NEAR(mu[0], 0.7 / 1.25, 1e-6);
    EXPECT_NEAR(mu[1], (0.2 + 0.25) / 1.25, 1e-6);
    EXPECT_NEAR(mu[2], 0.1 / 1.25, 1e-6);
    EXPECT_EQ(label, 0);  // a small psi keeps the old label for a while: temporal smoothing
}

// ---- the whole clustering on synthetic scenes --------------------------------------------

namespace {

SceneBox box(float x, float z, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    SceneBox s;
    s.x = x;
    s.z = z;
    s.r = r;
    s.g = g;
    s.b = b;
    return s;
}

Scene table_with_boxes() {
    Scene s;
    s.boxes = {box(-0.35f, 1.1f, 220, 30, 30), box(0.0f, 1.0f, 30, 190, 40),
               box(0.35f, 1.15f, 40, 60, 220), box(0.12f, 1.45f, 230, 210, 40)};
    s.noise_seed = 7;
    return s;
}

// Runs one frame through normals, range selection and clustering.
struct Runner {
    explicit Runner(const ClusterParams& p) : state(p) {}
    const LabelImage& step(const Scene& scene, std::vector<int>* truth = nullptr) {
        const RgbdFrame f = render_scene(scene, truth);
        back_project(f, cloud);
        estimate_normals(NormalParams{}, cloud, normals);
        select_depth_range(DepthRange{}, cloud, active);
        stats = state.step(cloud, normals, active, labels);
        return labels;
    }
    ClusterState state;
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active;
    LabelImage labels;
    FrameStats stats;
};

}  // namespace

TEST(ClusterState, EveryBoxIsCoveredByOneDominantCluster) {
    Runner run(ClusterParams::paper());  // k = 7 for a table, a wall and 4 boxes
    std::vector<int> truth;
    for (int frame = 0; frame < 10; ++frame) {
        Scene s = table_with_boxes();
        s.noise_seed = 7 + static_cast<std::uint32_t>(frame);
        run.step(s, &truth);
    }
    std::set<int> box_labels;
    for (int i = 0; i < 4; ++i) {
        int dominant = -1;
        const double purity = dominant_share(run.labels.labels, truth, kTruthBox0 + i, &dominant);
        EXPECT_GE(purity, 0.95) << "box " << i;
        EXPECT_GT(dominant, 0);
        box_labels.insert(dominant);
    }
    EXPECT_EQ(box_labels.size(), 4u) << "two boxes share a cluster";
}

TEST(ClusterState, LabelsCoverEveryActivePixel) {
    Runner run(ClusterParams::paper());
    run.step(table_with_boxes());
    for (std::size_t p = 0; p < run.active.size(); ++p) {
        if (run.active[p]) {
            ASSERT_GE(run.labels.labels[p], 1) << p;
            ASSERT_LE(run.labels.labels[p], 7) << p;
        } else {
            ASSERT_EQ(run.labels.labels[p], 0) << p;
        }
    }
    EXPECT_TRUE(run.stats.seeded);
    EXPECT_EQ(run.stats.tau, 1);
}

TEST(ClusterState, ObjectAppearingMidSequenceGetsItsOwnClusterWithin5Frames) {
    Runner run(ClusterParams::paper());
    Scene before = table_with_boxes();
    before.boxes.pop_back();  // three boxes at first
    for (int frame = 0; frame < 8; ++frame) run.step(before);
    const Scene after = table_with_boxes();  // the yellow box appears
    std::vector<int> truth;
    for (int frame = 0; frame < 5; ++frame) run.step(after, &truth);
    int newcomer = -1;
    EXPECT_GE(dominant_share(run.labels.labels, truth, kTruthBox0 + 3, &newcomer), 0.95);
    for (int i = 0; i < 3; ++i) {
        int other = -1;
        dominant_share(run.labels.labels, truth, kTruthBox0 + i, &other);
        EXPECT_NE(other, newcomer) << "the new box shares box " << i << "'s cluster";
    }
    // and the cluster is its own: most of that cluster's pixels lie on the new box (k-means
    // may still lend it a strip of the table around the box)
    std::size_t on_box = 0, total = 0;
    for (std::size_t p = 0; p < truth.size(); ++p)
        if (run.labels.labels[p] == newcomer) {
            ++total;
            on_box += truth[p] == kTruthBox0 + 3;
        }
    EXPECT_GT(static_cast<double>(on_box) / static_cast<double>(total), 0.5);
}

TEST(ClusterState, ObjectLeavingLosesItsWeightAfterOneFrame) {
    Runner run(ClusterParams::paper());
    std::vector<int> truth;
    const Scene with = table_with_boxes();
    for (int frame = 0; frame < 6; ++frame) run.step(with, &truth);
    int red = -1;
    ASSERT_GE(dominant_share(run.labels.labels, truth, kTruthBox0, &red), 0.95);
    const std::vector<int> truth_with = truth;

    Scene without = with;
    without.boxes.erase(without.boxes.begin());  // the red box leaves
    run.step(without, &truth);
    std::size_t checked = 0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
        if (truth_with[p] != kTruthBox0 || !run.active[p]) continue;
        const int u = static_cast<int>(p % run.labels.width), v = static_cast<int>(p / run.labels.width);
        const PixelWeights& mu = run.state.weights(run.state.grid_index(u, v));
        EXPECT_LE(mu.weight(red - 1), 0.5f + 1e-4f);
        EXPECT_NE(run.labels.labels[p], red) << p;
        ++checked;
    }
    EXPECT_GT(checked, 500u);
}

TEST(ClusterState, InactivePixelsKeepTheirWeights) {
    Runner run(ClusterParams::paper());
    run.step(table_with_boxes());
    const int g = run.state.grid_index(160, 200);
    const PixelWeights before = run.state.weights(g);
    // The same scene with the table pixel (160, 200) removed from the active set.
    const RgbdFrame f = render_scene(table_with_boxes());
    back_project(f, run.cloud);
    estimate_normals(NormalParams{}, run.cloud, run.normals);
    select_depth_range(DepthRange{}, run.cloud, run.active);
    run.active[static_cast<std::size_t>(200) * 320 + 160] = 0;
    run.state.step(run.cloud, run.normals, run.active, run.labels);
    const PixelWeights& after = run.state.weights(g);
    int total = 0;
    for (int s = 0; s < PixelWeights::kSlots; ++s) total += before.mu[s];
    EXPECT_NEAR(total, PixelWeights::kOne, 8);
    for (int s = 0; s < PixelWeights::kSlots; ++s) {
        EXPECT_EQ(before.cluster[s], after.cluster[s]);
        EXPECT_EQ(before.mu[s], after.mu[s]);
    }
    EXPECT_EQ(run.labels.labels[static_cast<std::size_t>(200) * 320 + 160], 0);
}

TEST(ClusterState, SameSeedSameLabelsWhateverTheThreadCount) {
    ClusterParams p = ClusterParams::paper();
    p.seed = 42;
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    Runner a(p);
    for (int i = 0; i < 3; ++i) a.step(table_with_boxes());
    omp_set_num_threads(std::max(2, threads));
    Runner b(p);
    for (int i = 0; i < 3; ++i) b.step(table_with_boxes());
    omp_set_num_threads(threads);
    EXPECT_EQ(a.labels.labels, b.labels.labels);
    p.seed = 43;
    Runner c(p);
    c.step(table_with_boxes());
    EXPECT_TRUE(c.state.seeded());
}

TEST(ClusterState, StrideSamplesTheGridAndStillLabelsItsPixels) {
    ClusterParams p = ClusterParams::paper();
    p.stride = 2;
    Runner run(p);
    std::vector<int> truth;
    for (int i = 0; i < 5; ++i) run.step(table_with_boxes(), &truth);
    EXPECT_EQ(run.state.grid_width(), 160);
    EXPECT_EQ(run.state.grid_height(), 120);
    EXPECT_LE(run.stats.points, run.active.size() / 4);
    for (int i = 0; i < 4; ++i)
        EXPECT_GE(dominant_share(run.labels.labels, truth, kTruthBox0 + i), 0.9) << i;
}

TEST(ClusterState, MoreClustersThanPointsIsAnInputError) {
    ClusterParams p;
    p.k = 5;
    ClusterState state(p);
    OrganizedCloud c;
    c.resize(4, 4);
    NormalMap n;
    n.resize(4, 4);
    std::vector<std::uint8_t> active(16, 0);
    active[0] = active[5] = active[10] = 1;
    for (std::size_t i : {0u, 5u, 10u}) {
        c.valid[i] = 1;
        c.z[i] = 1.0f + static_cast<float>(i);
    }
    LabelImage labels;
    EXPECT_THROW(state.step(c, n, active, labels), InputError);
}

TEST(ClusterState, DepthOnlyFramesClusterOnGeometry) {
    Runner run(ClusterParams::paper());
    Scene s = table_with_boxes();
    RgbdFrame f = render_scene(s);
    f.color = ColorImage{};
    back_project(f, run.cloud);
    estimate_normals(NormalParams{}, run.cloud, run.normals);
    select_depth_range(DepthRange{}, run.cloud, run.active);
    for (int i = 0; i < 3; ++i) run.state.step(run.cloud, run.normals, run.active, run.labels);
    std::set<int> used(run.labels.labels.begin(), run.labels.labels.end());
    used.erase(0);
    EXPECT_GE(used.size(), 3u);  // geometry alone still splits the scene
}

// ---- kept weights (PixelWeights) against dense float weights ---------------------------

TEST(PixelWeights, UpdateMatchesDenseWhileTheWinnersFitInTheSlots) {
    constexpr int S = PixelWeights::kSlots, k = S + 2;
    PixelWeights w;
    std::vector<float> dense(k, 0.0f);
    // S distinct winners, some more than once: all kept, so kept = dense (to 16 bits).
    std::vector<int> winners;
    for (int j = 0; j < S; ++j) winners.push_back((j * 3) % S);
    for (int j = 0; j < S; j += 2) winners.push_back(j);
    for (int winner : winners) {
        const int label = update_weights(w, winner, 0.6f);
        EXPECT_EQ(label, update_weights(dense.data(), k, winner, 0.6f));
        float sum = 0;
        for (int s = 0; s < S; ++s) sum += static_cast<float>(w.mu[s]) / PixelWeights::kOne;
        EXPECT_NEAR(sum, 1.0f, 1e-4f);
    }
    for (int j = 0; j < k; ++j) EXPECT_NEAR(w.weight(j), dense[j], 1e-4f) << j;
    // One more cluster wins: the smallest kept weight is dropped, the rest renormalize.
    int smallest = 0;
    for (int j = 0; j < S; ++j)
        if (dense[j] < dense[smallest]) smallest = j;
    update_weights(w, S, 0.6f);
    EXPECT_EQ(w.weight(smallest), 0.0f);
    EXPECT_NEAR(w.weight(S), 0.6f / 1.6f, 1e-3f);
}

TEST(PixelWeights, NewPixelTakesTheWinnerAndPsiOneHalves) {
    PixelWeights w;
    EXPECT_EQ(update_weights(w, 5, 1.0f), 5);
    EXPECT_FLOAT_EQ(w.weight(5), 1.0f);
    EXPECT_EQ(update_weights(w, 2, 1.0f), 2);  // a tie at 0.5: the newest winner
    EXPECT_NEAR(w.weight(5), 0.5f, 1e-4f);
    EXPECT_NEAR(w.weight(2), 0.5f, 1e-4f);
}

TEST(PixelWeights, VectorUpdateMatchesScalar) {
    // update_weights (SSE2 where the build has it) against detail::update_weights_scalar,
    // bit for bit: on the states that updates reach, and on arbitrary ones with ties, zeros
    // and repeated ids, which exercise every tie rule of the slot search and the arg-max.
    std::mt19937 rng(7);
    auto run = [](PixelWeights a, int winner, float psi) {
        PixelWeights b = a;
        const int la = update_weights(a, winner, psi);
        const int lb = detail::update_weights_scalar(b, winner, psi);
        const bool same = la == lb && std::memcmp(&a, &b, sizeof a) == 0;
        return std::make_pair(same, a);
    };
    const float psis[] = {1.0f, 0.5f, 0.25f, 0.1f, 0.013f};
    int mismatches = 0, swaps = 0, replaced = 0;
    for (int seq = 0; seq < 2000; ++seq) {  // reachable states: sequences of winners
        const int k = std::uniform_int_distribution<int>(1, 12)(rng);
        const float psi = psis[seq % 5];
        PixelWeights w;
        for (int t = 0; t < 40; ++t) {
            const int winner = std::uniform_int_distribution<int>(0, k - 1)(rng);
            bool kept = false;
            for (int s = 0; s < PixelWeights::kSlots; ++s) kept |= w.mu[s] > 0 && w.cluster[s] == winner;
            replaced += !kept;
            auto [same, next] = run(w, winner, psi);
            mismatches += !same;
            swaps += next.mu[0] == 65535 && next.cluster[0] == winner && w.cluster[0] != winner;
            w = next;
        }
    }
    std::uniform_int_distribution<int> small(0, 3), id(0, 7);
    const std::uint16_t levels[] = {0, 1, 20000, 65535};
    for (int t = 0; t < 200000; ++t) {  // arbitrary states
        PixelWeights w;
        for (int s = 0; s < PixelWeights::kSlots; ++s) {
            w.cluster[s] = static_cast<std::uint16_t>(id(rng));
            w.mu[s] = t % 2 ? levels[small(rng)] : static_cast<std::uint16_t>(rng());
        }
        mismatches += !run(w, id(rng), psis[t % 5]).first;
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(replaced, 1000);  // both branches of the slot search ran
    EXPECT_GT(swaps, 10);       // and the swap to slot 0
}

namespace {
// Replays a real sequence (frames repeated `rounds` times) through the clustering and,
// from the same winners, through dense float weights; returns the share of active pixels
// whose arg-max agrees, and the largest colour difference (eq. 9, 0-255) seen.
void compare_with_dense(const std::string& input, int k, float psi, int rounds,
                        double& label_agreement, double& colour_within_2) {
    auto source = open_source((sample_dir() / input).string(), SourceOptions{});
    ClusterParams p = ClusterParams::paper();
    p.k = k;
    p.psi = psi;
    ClusterState state(p);
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> active;
    LabelImage labels;
    SourceItem item;
    std::vector<float> dense;
    std::vector<int> winners;
    std::size_t compared = 0, agree = 0, colour_compared = 0, colour_ok = 0;
    std::vector<double> palette;
    for (int j = 0; j < k; ++j)
        for (int q = 0; q < 3; ++q) palette.push_back(cluster_color(j)[q]);
    for (int round = 0; round < rounds; ++round)
        for (std::size_t f = 0; f < source->size(); ++f) {
            source->read(f, item);
            back_project(item.frame, cloud);
            estimate_normals(NormalParams{}, cloud, normals);
            select_depth_range(DepthRange{}, cloud, active);
            state.step(cloud, normals, active, labels);
            state.last_winners(winners);
            dense.resize(winners.size() * static_cast<std::size_t>(k), 0.0f);
            for (std::size_t g = 0; g < winners.size(); ++g) {
                if (winners[g] < 0) continue;
                float* mu = dense.data() + g * k;
                const int label = update_weights(mu, k, winners[g], psi);
                ++compared;
                agree += labels.labels[g] == label + 1;
                if (g % 5 != 0) continue;  // colours on a fifth of the pixels: enough, and fast
                const PixelWeights& kept = state.weights(static_cast<int>(g));
                bool ok = true;
                for (int q = 0; q < 3; ++q) {
                    double a = 0, b = 0;
                    for (int j = 0; j < k; ++j) a += mu[j] * palette[3 * j + q];
                    for (int s = 0; s < PixelWeights::kSlots; ++s)
                        b += kept.mu[s] / PixelWeights::kOne * palette[3 * kept.cluster[s] + q];
                    ok = ok && std::abs(a - b) <= 2.0;
                }
                ++colour_compared;
                colour_ok += ok;
            }
        }
    label_agreement = static_cast<double>(agree) / static_cast<double>(compared);
    colour_within_2 = static_cast<double>(colour_ok) / static_cast<double>(colour_compared);
}
}  // namespace

TEST(PixelWeights, LabelsAndColoursMatchDenseFloatWeightsOnRealSequences) {
    struct Case {
        const char* input;
        int k;
        float psi;
    };
    for (const Case c : {Case{"uois_tabletop", 10, 1.0f}, Case{"uois_tabletop", 50, 1.0f},
                         Case{"uois_tabletop", 10, 0.3f}, Case{"pcl_kinect/pairwise_seq", 30, 0.5f}}) {
        double labels = 0, colours = 0;
        compare_with_dense(c.input, c.k, c.psi, 2, labels, colours);
        EXPECT_GE(labels, 0.995) << c.input << " k " << c.k << " psi " << c.psi;
        EXPECT_GE(colours, 0.99) << c.input << " k " << c.k << " psi " << c.psi;
        std::printf("%s k=%d psi=%.1f: same arg-max %.4f, colour within 2 levels %.4f\n",
                    c.input, c.k, c.psi, labels, colours);
    }
}
