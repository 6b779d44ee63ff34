#pragma once
// Private to the library: the PNG encoder of what wul3d writes (labels, colours, masks, depth).
#include <cstddef>
#include <vector>

struct libdeflate_compressor;

namespace wul3d::detail {

/// What an image holds, which decides how it is compressed.
enum class PngContent {
    /// Labels and masks: areas of one value, most rows like the one above. The Up filter
    /// leaves runs of zeros, which a run-length deflate takes at memory speed (for files about
    /// twice as large as zlib's run-length level writes).
    Regions,
    /// Colours and depth: no long runs. libdeflate's fastest level on the unfiltered rows
    /// (faster than any filter and zlib's fastest level, and smaller files).
    Picture,
};

/// Encodes images to PNG files, reusing its buffers and compressor from image to image
/// (fresh ones, a megabyte of new pages, cost a third of a picture's encode). One thread at
/// a time.
class PngEncoder {
public:
    PngEncoder() = default;
    ~PngEncoder();
    PngEncoder(const PngEncoder&) = delete;
    PngEncoder& operator=(const PngEncoder&) = delete;

    /// `height` rows of `width` pixels at `pixels` (8-bit grey, 8-bit RGB with channels 3, or
    /// 16-bit grey in the host's byte order with bits 16; no padding) as a PNG file in `out`:
    /// signature, IHDR, one IDAT chunk, IEND. Throws IoError (without a path: the caller adds
    /// it) for an empty image or one whose file would pass PNG's limits.
    void encode(int width, int height, int bits, int channels, const void* pixels, PngContent content,
                std::vector<unsigned char>& out);

private:
    /// The zlib stream of Regions, row by row: Up filter, then runs of the byte before.
    void deflate_regions(std::size_t height, std::size_t row_bytes, int bits, const void* pixels);
    /// The zlib stream of a Picture: the rows unfiltered, then libdeflate at once.
    void deflate_picture(std::size_t height, std::size_t row_bytes, int bits, const void* pixels);

    libdeflate_compressor* compressor_ = nullptr;  ///< Picture's, made on first use
    std::vector<unsigned char> rows_;    ///< Regions: one filtered row; Picture: all rows
    std::vector<unsigned char> stream_;  ///< the zlib stream, stream_bytes_ of it used
    std::size_t stream_bytes_ = 0;
};

}  // namespace wul3d::detail
