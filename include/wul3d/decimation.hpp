#pragma once
/// @file decimation.hpp
/// The optional first and last stage (PipelineParams::decimation, `--decimate N`): the frame
/// shrinks by N in u and v before back-projection, every later stage runs on N^2 times fewer
/// pixels, and each per-pixel result is carried back to the input's pixels at the end.
/// The speed/quality trade-off is measured in docs/SPEED.md ("Decimation").
#include <cstddef>
#include <memory>

#include "wul3d/depth_range.hpp"
#include "wul3d/frame.hpp"

namespace wul3d {

/// Each N x N block of `in` becomes one pixel of `out` ((W + N - 1) / N x (H + N - 1) / N):
/// the block's first pixel in row-major order with depth in `range` (when given), else its
/// first with valid depth; its depth and colour both (never an average: a block across an
/// object's edge would get a depth between the two surfaces). With the range, a block is in
/// it whenever one of its pixels is, so that every input pixel in range has a block in range
/// to take its results from. A block without depth takes its top-left colour. The
/// intrinsics scale to the top-left samples (fx / N, cx / N); a block whose top-left pixel
/// is not the one kept is back-projected up to N - 1 pixels off, a sub-pixel error at the
/// decimated resolution.
/// N = 1 copies. Throws ParamError for N outside [1, 8] and InputError for a colour image
/// whose size differs from the depth's.
void decimate_frame(const RgbdView& in, int factor, RgbdFrame& out,
                    const DepthRange* range = nullptr);
inline void decimate_frame(const RgbdFrame& in, int factor, RgbdFrame& out,
                           const DepthRange* range = nullptr) {
    decimate_frame(in.view(), factor, out, range);
}

struct FrameResult;  // frame_result.hpp

/// What the way back (expand_result) needs of the pipeline's parameters.
struct ExpandParams {
    int factor = 2;  ///< the frame was decimated by it (PipelineParams::decimation), [2, 8]
    /// An input pixel is on a block's surface within same_m + same_rel z^2 metres of its
    /// depth z (the pipeline: the segmentation's depth jump over a block's width, N times it).
    float same_m = 0.0f, same_rel = 0.0f;
    DepthRange range;  ///< the frame was decimated with it; a pixel out of it is no point
    /// false: the result of the paper's steps only (labels, colours, active points); the
    /// outlines placed by colour are the clusters' then, not the objects'.
    bool objects = true;
    /// false: r.colors is left empty (PipelineParams::render_colors; `small` has none).
    bool colors = true;
    std::size_t min_object_pixels = 0;  ///< objects under it (input pixels) are dropped
};

/// expand_result's buffers, reused from frame to frame (opaque: decimation.cpp).
class ExpandWorkspace {
public:
    ExpandWorkspace();
    ~ExpandWorkspace();
    ExpandWorkspace(ExpandWorkspace&&) noexcept;
    ExpandWorkspace& operator=(ExpandWorkspace&&) noexcept;

private:
    struct Buffers;
    std::unique_ptr<Buffers> b_;
    friend void expand_result(const ExpandParams&, const RgbdView&, const RgbdFrame&, const FrameResult&,
                              ExpandWorkspace&, FrameResult&);
};

/// The last stage with decimation: `small`, the results of the stages on `decimated` (`frame`
/// decimated by params.factor with decimate_frame and params.range), carried back to
/// `frame`'s pixels into `out`. Each per-pixel result (labels, colours where params.colors,
/// active points, plane classes, segments, objects) comes from the pixel's source block: its
/// own when its depth is on the block's surface, else the nearest in depth of the 3 x 3
/// blocks around; at the objects' outlines (the clusters' without params.objects) the
/// input's colour places the outline (src/stages/decimated_source.hpp gives the rules). A
/// pixel out of the depth range, or without a source, is no point. Each object's pixels and
/// 2D box are counted again at the input's size, and objects left under
/// params.min_object_pixels are dropped. Everything else of `small` (stats, plane,
/// object_list) is copied; `out.times` is not set. The same bytes on any number of threads;
/// no allocation from the second frame of a size on.
/// Throws InputError for a `decimated` frame or colour that does not match `frame`.
void expand_result(const ExpandParams& params, const RgbdView& frame, const RgbdFrame& decimated,
                   const FrameResult& small, ExpandWorkspace& ws, FrameResult& out);

}  // namespace wul3d
