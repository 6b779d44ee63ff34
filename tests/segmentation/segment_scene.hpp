#pragma once
// What the segmentation tests share (tests/segmentation/*_test.cpp, one per rule): scenes
// rendered up to the plane stage, segmented with given parameters, and the test that two
// truth objects come out as two objects.
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "synthetic_scene.hpp"
#include "wul3d/background.hpp"
#include "wul3d/normals.hpp"
#include "wul3d/plane.hpp"
#include "wul3d/segmentation.hpp"

namespace wul3d::test {

/// A rendered scene with what segmentation takes: the cloud, normals and plane classes.
struct PlaneStage {
    std::vector<int> truth;
    OrganizedCloud cloud;
    NormalMap normals;
    std::vector<std::uint8_t> classes;
    PlaneResult plane;
};

/// Runs normals, depth range and support-plane removal on a rendered frame `f` whose truth
/// ids are `truth` (render_scene's; a test may change the frame in between).
inline PlaneStage up_to_the_plane(const RgbdFrame& f, std::vector<int> truth) {
    PlaneStage st;
    st.truth = std::move(truth);
    std::vector<std::uint8_t> active;
    back_project(f, st.cloud);
    estimate_normals(NormalParams{}, st.cloud, st.normals);
    select_depth_range(DepthRange{}, st.cloud, active);
    PlaneWorkspace pws;
    st.plane = remove_support_plane(PlaneParams{}, f.intrinsics, st.cloud, st.normals, active, pws,
                                    st.classes);
    EXPECT_TRUE(st.plane.found);
    return st;
}

/// Renders `s` and runs normals, depth range and support-plane removal.
inline PlaneStage up_to_the_plane(const Scene& s) {
    std::vector<int> truth;
    const RgbdFrame f = render_scene(s, &truth);
    return up_to_the_plane(f, std::move(truth));
}

/// Segments a scene up to the plane stage.
inline LabelImage segment(const PlaneStage& in, const SegmentParams& params, SegmentStats* stats = nullptr) {
    SegmentWorkspace ws;
    LabelImage out;
    const SegmentStats st = segment_objects(params, in.cloud, in.normals, in.classes,
                                            &in.plane.support,
                                            in.plane.low_found ? &in.plane.low_support : nullptr, LabelImage{}, ws,
                                            out);
    if (stats) *stats = st;
    return out;
}

/// Renders `s` and runs normals, depth range, support-plane removal and segmentation.
inline LabelImage segment(const Scene& s, const SegmentParams& params, std::vector<int>& truth,
                   SegmentStats* stats = nullptr) {
    const PlaneStage in = up_to_the_plane(s);
    truth = in.truth;
    return segment(in, params, stats);
}

inline LabelImage segment(const Scene& s, Segmenter segmenter, std::vector<int>& truth,
                   SegmentStats* stats = nullptr) {
    SegmentParams params;
    params.segmenter = segmenter;
    return segment(s, params, truth, stats);
}

/// Truth objects `ta` and `tb` each come out mostly as one object (shares over `share`), and
/// as two different objects.
inline void expect_separate(const LabelImage& out, const std::vector<int>& truth, int ta, int tb, double share,
                     const char* what) {
    int a = 0, b = 0;
    EXPECT_GT(dominant_share(out.labels, truth, ta, &a), share);
    EXPECT_GT(dominant_share(out.labels, truth, tb, &b), share);
    EXPECT_NE(a, 0);
    EXPECT_NE(b, 0);
    EXPECT_NE(a, b) << what;
}

}  // namespace wul3d::test
