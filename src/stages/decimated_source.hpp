#pragma once
// The source block of each input pixel on the way back from decimation (decimation.hpp's
// expand_result): private to the library; the tests check the rules through it.
#include <cmath>
#include <cstdint>
#include <vector>

#include "wul3d/frame.hpp"

namespace wul3d {

/// The colour vote's buffers (DecimatedSource::use_colour_at_edges), owned by the caller and
/// reused from frame to frame: no allocation once sized.
struct VoteBuffers {
    /// Each edge block's source after the vote (a block index, its own when it keeps its
    /// label); sized to the decimated image, other blocks' entries untouched.
    std::vector<std::int32_t> block_source;
    /// The decimated frame as the vote reads it, padded by the grid's reach on every side
    /// (depth 0 there: no tap is on the surface, and a sum plus 0 is the sum): per block its
    /// depth and label (depth | label << 16), and its colour (r | g << 8 | b << 16).
    std::vector<std::uint32_t> depth_label, rgb;
    /// The edge blocks' indices, a whole number of lanes.
    std::vector<std::int32_t> edges;
    int padded_width = 0, padded_height = 0;
};

/// Which pixel of the decimated frame an input pixel takes its results from: the rules of
/// expand_result, pixel by pixel (decimation.cpp applies them a row at a time, and the tests
/// hold the two equal). An input pixel
/// without depth has none (-1). One with depth z is on the surface of a block whose depth is
/// within same_m + same_rel z^2 (metres) of z. It takes its own block when on its surface,
/// else the one of the 3 x 3 neighbouring blocks nearest to z in depth (an edge pixel whose
/// block was sampled on the other surface), else none when none of them has depth.
///
/// With use_colour_at_edges, colour places the outlines, in two steps:
/// 1. A colour vote, once per edge block (one whose 3 x 3 neighbourhood holds another
///    label), as in joint bilateral upsampling: the blocks on its surface on a 5 x 5 grid,
///    two blocks apart, centred on it, vote for their labels with the weight
///    exp(-|c_edge - c_block|^2 / (2 kColourSigma^2)). When the other labels together
///    outweigh its own, the edge block takes its results from the block nearest to it in
///    colour among theirs. This moves an outline that the decimated stages put a block or two
///    off (where normals over twice the distance blur a foot or a crease) to the colour edge.
/// 2. Per pixel, in an edge block: among its own block and the three beside the block's
///    quarter it lies in (left or right, above or below, and the corner between) that are
///    on its surface, the one nearest in colour (its own on a tie), through the block's
///    vote: the outline follows the input's colour edge instead of the blocks' staircase.
class DecimatedSource {
public:
    /// Throws InputError unless `decimated` is `input` decimated by `factor` in size.
    DecimatedSource(const DepthImage& input, const DepthImage& decimated, int factor,
                    float same_m, float same_rel);
    /// The same for an input depth of `width` x `height` at `input` (packed rows), in units
    /// of `scale_m_per_unit` metres.
    DecimatedSource(const std::uint16_t* input, int width, int height, float scale_m_per_unit,
                    const DepthImage& decimated, int factor, float same_m, float same_rel);
    /// `edge_blocks`: one flag (0 or 1) per decimated pixel (results differ from a neighbour's);
    /// `block_labels`: the label each decimated pixel votes for (objects, or clusters). They
    /// and the colour images stay owned by the caller, and so do `buffers`, whose
    /// block_source receives each edge block's vote.
    /// Ignored for frames without colour. Throws InputError for colour images of other sizes
    /// than the depths'.
    void use_colour_at_edges(const ColorImage& input, const ColorImage& decimated,
                             const std::uint8_t* edge_blocks, const std::uint16_t* block_labels,
                             VoteBuffers& buffers);
    /// The same with the input colour at `input_rgb` (packed RGB rows of the input depth's
    /// size; nullptr: none).
    void use_colour_at_edges(const std::uint8_t* input_rgb, const ColorImage& decimated,
                             const std::uint8_t* edge_blocks, const std::uint16_t* block_labels,
                             VoteBuffers& buffers);

    /// The vote's colour scale (distance between 8-bit RGB triples), chosen with the grid on
    /// the OSD learn frames and slide_learn38 at N = 2 (docs/DESIGN.md, decimation).
    static constexpr float kColourSigma = 20.0f;

    int factor() const { return factor_; }
    /// The decimated pixel (v' w + u') for input pixel (u, v), or -1.
    std::int32_t operator()(int u, int v) const { return in_block(u, v, u / factor_, v / factor_); }
    /// The same, for loops that step the block (bu, bv) = (u / factor, v / factor) themselves
    /// (a division per pixel costs more than the rest of the test).
    std::int32_t in_block(int u, int v, int bu, int bv) const {
        const std::size_t p = static_cast<std::size_t>(v) * W_ + u;
        const float z = full_[p];
        if (z == 0) return -1;
        const std::int32_t own = bv * w_ + bu;
        const bool on_own = same_surface(own, z);
        if (on_own && !(edges_ && edges_[own])) return own;
        return search(u, v, bu, bv, z, on_own);
    }
    /// Of the 3 x 3 blocks around block (bu, bv) that have depth (and a flag in `among`, one
    /// per block, when given), the one nearest to depth z (the image's units), or -1: a
    /// first-found on ties, rows top to bottom.
    std::int32_t nearest_in_depth(int bu, int bv, float z, const std::uint8_t* among) const;
    /// The surface test's limits in the depth images' units (same_surface's), for the loops
    /// that run it a row at a time: the same float operations, the same answers.
    float same_units() const { return same_; }
    float same_rel_units() const { return same_rel_; }

private:
    bool same_surface(std::int32_t q, float z) const {
        return small_[q] != 0 && std::fabs(small_[q] - z) <= same_ + same_rel_ * z * z;
    }
    /// The search of an edge pixel, or of one off its own block's surface.
    std::int32_t search(int u, int v, int bu, int bv, float z, bool on_own) const;
    /// Step 1 of the colour placement: each edge block's source after the vote, into
    /// buffers.block_source.
    void vote(const std::uint16_t* labels, VoteBuffers& buffers) const;

    const std::uint16_t* full_;
    const std::uint16_t* small_;
    int W_, H_, w_, h_, factor_;
    float same_, same_rel_;  ///< in the depth images' units
    const std::uint8_t* rgb_ = nullptr;        ///< input colour, with use_colour_at_edges
    const std::uint8_t* small_rgb_ = nullptr;  ///< decimated colour
    const std::uint8_t* edges_ = nullptr;      ///< edge blocks
    const std::int32_t* voted_ = nullptr;      ///< each block's source after the vote
};

}  // namespace wul3d
