#pragma once
// Private to src/io/: the PNG decoder of the common kinds a frame comes in (8-bit RGB colour,
// 16-bit grey depth, 8- or 16-bit grey labels, not interlaced), libdeflate's inflate and
// wul3d's own unfiltering in place of libpng's. libpng decodes every other kind, and every
// file this decoder does not take as it is.
#include <cstddef>

namespace wul3d::detail {

struct ImageScratch;

/// The pixels of `png` (`size` bytes that passed check_png: its chunks whole, their CRCs
/// right) into `out`: `height` rows of `width` pixels of `bytes_per_pixel` bytes (1: 8-bit
/// grey, 2: 16-bit grey, in the host's byte order, 3: 8-bit RGB), no padding. The caller has
/// read the header with libpng and asks only for the file's own kind, not interlaced.
/// Returns false where the image data is not exactly what the header says (the inflated
/// data longer or shorter, a corrupt stream or Adler-32, a filter type past 4, IDAT chunks
/// apart): libpng then decodes the file and says what is wrong, or accepts what it accepts.
/// Cost: one inflate (libdeflate) and one pass over the rows; s.inflated (and s.idat, for
/// a file of several IDAT chunks) grow once.
bool decode_png_rows(const unsigned char* png, std::size_t size, std::size_t width, std::size_t height,
                     int bytes_per_pixel, unsigned char* out, ImageScratch& s);

}  // namespace wul3d::detail
