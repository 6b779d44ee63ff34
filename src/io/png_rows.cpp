// The PNG decoder of the common kinds (png_rows.hpp). libpng inflates with zlib and undoes
// the Paeth filter, the one most encoders choose for photographs and depth, with a branch per
// byte that mispredicts: reading a frame cost as much as processing it (docs/SPEED.md). Here
// libdeflate inflates the rows at once and the filters are undone without branches (PNG
// specification, section 9: filter types 0-4).
#include "png_rows.hpp"

#include <libdeflate.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "branch_free.hpp"
#include "io_detail.hpp"
#include "png_format.hpp"

namespace wul3d::detail {

ImageScratch::Inflater::~Inflater() {
    if (d_ != nullptr) libdeflate_free_decompressor(d_);
}

libdeflate_decompressor* ImageScratch::Inflater::get() {
    if (d_ == nullptr) d_ = libdeflate_alloc_decompressor();
    return d_;
}

namespace {

/// The zlib stream of the IDAT chunks of `png` (checked: every chunk lies within `size`): the
/// one chunk's data in place, or several joined in s.idat. False if IDAT chunks lie apart
/// (libpng refuses that) or there is none.
bool idat_stream(const unsigned char* png, std::size_t size, ImageScratch& s, const unsigned char*& data,
                 std::size_t& n) {
    int runs = 0, chunks = 0;
    bool in_run = false;
    s.idat.clear();
    for (std::size_t pos = kPngSignature.size(); pos + 12 <= size;) {
        const std::size_t len = read_be32(png + pos);
        const bool idat = std::memcmp(png + pos + 4, "IDAT", 4) == 0;
        if (idat) {
            if (!in_run) ++runs;
            if (chunks++ == 0) {
                data = png + pos + 8;
                n = len;
            } else {
                if (chunks == 2) s.idat.assign(data, data + n);
                s.idat.insert(s.idat.end(), png + pos + 8, png + pos + 8 + len);
            }
        }
        in_run = idat;
        if (std::memcmp(png + pos + 4, "IEND", 4) == 0) break;
        pos += 12 + len;
    }
    if (runs != 1) return false;
    if (chunks > 1) {
        data = s.idat.data();
        n = s.idat.size();
    }
    return true;
}

/// Paeth's predictor (PNG specification 9.4) without a branch: a, b or c, whichever is
/// nearest to a + b - c, ties to a, then b.
inline int paeth(int a, int b, int c) {
    const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
    return pick(pa <= std::min(pb, pc), a, pick(pb <= pc, b, c));
}

/// Sub (1), Average (3) or Paeth (4) undone on bytes [first, n) of a row, the pixel to the
/// left kept in registers: a and c, one per byte of the pixel, as they stand at `first`.
template <int bpp, int filter>
void unfilter_left(const unsigned char* __restrict raw, const unsigned char* __restrict prior,
                   unsigned char* __restrict out, std::size_t first, std::size_t n, int (&a)[bpp], int (&c)[bpp]) {
    for (std::size_t i = first; i + bpp <= n; i += bpp)  // n is a whole number of pixels
        for (int k = 0; k < bpp; ++k) {
            const int b = prior[i + k];
            const int predicted = filter == 1 ? a[k] : filter == 3 ? (a[k] + b) >> 1 : paeth(a[k], b, c[k]);
            a[k] = static_cast<unsigned char>(raw[i + k] + predicted);
            c[k] = b;
            out[i + k] = static_cast<unsigned char>(a[k]);
        }
}

#if defined(__SSE2__)
/// The bpp bytes at p (2 or 3; for 3, four are read) in 16-bit lanes.
template <int bpp>
__m128i load_pixel(const unsigned char* p) {
    std::uint32_t v = 0;
    std::memcpy(&v, p, bpp == 3 ? 4 : 2);
    return _mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(v)), _mm_setzero_si128());
}

/// |x| per 16-bit lane.
inline __m128i abs16(__m128i x) { return _mm_max_epi16(x, _mm_sub_epi16(_mm_setzero_si128(), x)); }

/// m ? x : y per lane (m all ones or all zeros).
inline __m128i select(__m128i m, __m128i x, __m128i y) {
    return _mm_or_si128(_mm_and_si128(m, x), _mm_andnot_si128(m, y));
}

/// The chain of a row under Average or Paeth: the pixel to the left (a) and the one above it
/// (c), a pixel's bytes in the 16-bit lanes of one register.
struct Chain {
    __m128i a = _mm_setzero_si128(), c = _mm_setzero_si128();

    /// a and c as unfilter_left takes them, one int per byte.
    template <int bpp>
    void to_ints(int (&a_out)[bpp], int (&c_out)[bpp]) const {
        alignas(16) std::int16_t lanes[8];
        _mm_store_si128(reinterpret_cast<__m128i*>(lanes), a);
        for (int k = 0; k < bpp; ++k) a_out[k] = lanes[k];
        _mm_store_si128(reinterpret_cast<__m128i*>(lanes), c);
        for (int k = 0; k < bpp; ++k) c_out[k] = lanes[k];
    }
};

/// Average (3) or Paeth (4) undone on the pixel at raw (the one above at prior) into out,
/// all its bytes at once: the chain from pixel to pixel, which sets the pace, is a pixel a
/// step rather than a byte. Reads and writes 4 bytes: a 3-byte pixel's fourth is the next
/// pixel's first, written again in the next step.
template <int bpp, int filter>
inline void unfilter_pixel(const unsigned char* raw, const unsigned char* prior, unsigned char* out, Chain& s) {
    const __m128i b = load_pixel<bpp>(prior), x = load_pixel<bpp>(raw);
    __m128i predicted;
    if constexpr (filter == 3) {
        predicted = _mm_srli_epi16(_mm_add_epi16(s.a, b), 1);
    } else {
        const __m128i bc = _mm_sub_epi16(b, s.c), ac = _mm_sub_epi16(s.a, s.c);
        const __m128i pa = abs16(bc), pb = abs16(ac), pc = abs16(_mm_add_epi16(bc, ac));
        const __m128i nearer_bc = select(_mm_cmpgt_epi16(pb, pc), s.c, b);
        predicted = select(_mm_cmpgt_epi16(pa, _mm_min_epi16(pb, pc)), nearer_bc, s.a);
    }
    s.c = b;
    s.a = _mm_and_si128(_mm_add_epi16(x, predicted), _mm_set1_epi16(0xff));
    const auto v = static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_packus_epi16(s.a, s.a)));
    std::memcpy(out, &v, bpp == 3 ? 4 : 2);
}

/// unfilter_pixel on the pixels of a row from byte i on, stopping before the pixel whose
/// 4-byte load or store would pass the row's end. Returns where it stopped.
template <int bpp, int filter>
std::size_t unfilter_sse2(const unsigned char* __restrict raw, const unsigned char* __restrict prior,
                          unsigned char* __restrict out, std::size_t i, std::size_t n, Chain& s) {
    for (; i + 4 <= n; i += bpp) unfilter_pixel<bpp, filter>(raw + i, prior + i, out + i, s);
    return i;
}

/// Two rows, each under Average or Paeth (filter0 the upper, filter1 the lower), undone
/// together: the lower row trails the upper by kTrail pixels, so that what it reads of the
/// upper was written steps before, and the two chains, independent, run side by side (one
/// row's chain leaves the core idle most of each step). Then each row's end by
/// unfilter_left.
template <int bpp, int filter0, int filter1>
void unfilter_pair(const unsigned char* raw0, const unsigned char* raw1, const unsigned char* prior,
                   unsigned char* out0, unsigned char* out1, std::size_t n) {
    constexpr std::size_t kTrail = 4 * bpp;
    Chain s0, s1;
    std::size_t i = 0;
    for (; i < kTrail && i + 4 <= n; i += bpp) unfilter_pixel<bpp, filter0>(raw0 + i, prior + i, out0 + i, s0);
    for (; i + 4 <= n; i += bpp) {
        unfilter_pixel<bpp, filter0>(raw0 + i, prior + i, out0 + i, s0);
        unfilter_pixel<bpp, filter1>(raw1 + i - kTrail, out0 + i - kTrail, out1 + i - kTrail, s1);
    }
    int a[bpp] = {}, c[bpp] = {};
    s0.to_ints<bpp>(a, c);
    unfilter_left<bpp, filter0>(raw0, prior, out0, i, n, a, c);
    const std::size_t i1 = unfilter_sse2<bpp, filter1>(raw1, out0, out1, i < kTrail ? 0 : i - kTrail, n, s1);
    s1.to_ints<bpp>(a, c);
    unfilter_left<bpp, filter1>(raw1, out0, out1, i1, n, a, c);
}
#endif

/// Sub, Average or Paeth on a row: SSE2 for Average and Paeth on 2- and 3-byte pixels (a
/// frame's depth and colour), the rest by unfilter_left.
template <int bpp, int filter>
void unfilter_pixels(const unsigned char* __restrict raw, const unsigned char* __restrict prior,
                     unsigned char* __restrict out, std::size_t n) {
    int a[bpp] = {}, c[bpp] = {};
    std::size_t first = 0;
#if defined(__SSE2__)
    if constexpr (filter != 1 && bpp > 1) {
        Chain s;
        first = unfilter_sse2<bpp, filter>(raw, prior, out, 0, n, s);
        s.to_ints<bpp>(a, c);
    }
#endif
    unfilter_left<bpp, filter>(raw, prior, out, first, n, a, c);
}

/// Row `raw` (n bytes, without its filter byte) unfiltered into `out`, the row above being
/// `prior` (zeros for the first row); bpp bytes a pixel. Left of the first pixel, the
/// specification's a and c are 0. The filters that depend on the pixel to the left (Sub,
/// Average, Paeth) keep it in registers, a and c one per byte of the pixel: each pixel's bytes
/// are then worked on side by side, with no wait for the store of the one before.
template <int bpp>
void unfilter_row(int filter, const unsigned char* __restrict raw, const unsigned char* __restrict prior,
                  unsigned char* __restrict out, std::size_t n) {
    if (filter == 0) {
        std::memcpy(out, raw, n);
        return;
    }
    if (filter == 2) {
        for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<unsigned char>(raw[i] + prior[i]);
        return;
    }
    switch (filter) {
        case 1: unfilter_pixels<bpp, 1>(raw, prior, out, n); break;
        case 3: unfilter_pixels<bpp, 3>(raw, prior, out, n); break;
        default: unfilter_pixels<bpp, 4>(raw, prior, out, n); break;  // the caller refused past 4
    }
}

/// Rows y and y + 1 by unfilter_pair when both are under Average or Paeth (on 2- and 3-byte
/// pixels, with SSE2: most rows of a frame's depth and colour); false otherwise.
template <int bpp>
bool unfilter_two_rows(int filter0, int filter1, const unsigned char* raw0, const unsigned char* raw1,
                       const unsigned char* prior, unsigned char* out0, unsigned char* out1, std::size_t n) {
#if defined(__SSE2__)
    if constexpr (bpp > 1) {
        const int both = filter0 * 8 + filter1;
        switch (both) {
            case 3 * 8 + 3: unfilter_pair<bpp, 3, 3>(raw0, raw1, prior, out0, out1, n); return true;
            case 3 * 8 + 4: unfilter_pair<bpp, 3, 4>(raw0, raw1, prior, out0, out1, n); return true;
            case 4 * 8 + 3: unfilter_pair<bpp, 4, 3>(raw0, raw1, prior, out0, out1, n); return true;
            case 4 * 8 + 4: unfilter_pair<bpp, 4, 4>(raw0, raw1, prior, out0, out1, n); return true;
            default: return false;
        }
    }
#endif
    (void)filter0, (void)filter1, (void)raw0, (void)raw1, (void)prior, (void)out0, (void)out1, (void)n;
    return false;
}

/// The `height` inflated rows at `in` (each its filter byte, then row_bytes) unfiltered into
/// `out`, two at a time where unfilter_two_rows takes them; false for a filter type past 4.
template <int bpp>
bool unfilter_rows(const unsigned char* in, std::size_t height, std::size_t row_bytes, unsigned char* out,
                   const unsigned char* zeros) {
    const unsigned char* prior = zeros;
    for (std::size_t y = 0; y < height;) {
        const unsigned char* const row = in + y * (row_bytes + 1);
        unsigned char* const dst = out + y * row_bytes;
        if (row[0] > 4) return false;
        if (y + 1 < height) {
            const unsigned char* const next = row + row_bytes + 1;
            if (next[0] > 4) return false;
            if (unfilter_two_rows<bpp>(row[0], next[0], row + 1, next + 1, prior, dst, dst + row_bytes, row_bytes)) {
                prior = dst + row_bytes;
                y += 2;
                continue;
            }
        }
        unfilter_row<bpp>(row[0], row + 1, prior, dst, row_bytes);
        prior = dst;
        ++y;
    }
    return true;
}

}  // namespace

bool decode_png_rows(const unsigned char* png, std::size_t size, std::size_t width, std::size_t height,
                     int bytes_per_pixel, unsigned char* out, ImageScratch& s) {
    const unsigned char* stream = nullptr;
    std::size_t stream_bytes = 0;
    if (!idat_stream(png, size, s, stream, stream_bytes)) return false;
    libdeflate_decompressor* const inflater = s.inflater.get();
    if (inflater == nullptr) return false;
    const std::size_t row_bytes = width * static_cast<std::size_t>(bytes_per_pixel);
    const std::size_t expected = height * (row_bytes + 1);
    // One byte more than the rows: a stream that inflates to more than the header says ends
    // with a byte there, not with an error that could also mean corrupt data.
    s.inflated.resize(expected + 1);
    std::size_t got = 0;
    if (libdeflate_zlib_decompress(inflater, stream, stream_bytes, s.inflated.data(), s.inflated.size(), &got) !=
            LIBDEFLATE_SUCCESS ||
        got != expected)
        return false;
    // The row above the first: zeros, in s.idat (the joined chunks, no longer read).
    s.idat.assign(row_bytes, 0);
    const unsigned char* const zeros = s.idat.data();
    bool ok = false;
    switch (bytes_per_pixel) {
        case 1: ok = unfilter_rows<1>(s.inflated.data(), height, row_bytes, out, zeros); break;
        case 2: ok = unfilter_rows<2>(s.inflated.data(), height, row_bytes, out, zeros); break;
        case 3: ok = unfilter_rows<3>(s.inflated.data(), height, row_bytes, out, zeros); break;
        default: return false;
    }
    if (!ok) return false;
    if (bytes_per_pixel == 2 && std::endian::native == std::endian::little) {
        // PNG's samples are big-endian; swapped once the rows (each the next one's prior)
        // are all unfiltered.
        const std::size_t n = width * height;
        for (std::size_t i = 0; i < n; ++i) {
            std::uint16_t v;
            std::memcpy(&v, out + 2 * i, 2);
            v = static_cast<std::uint16_t>((v >> 8) | (v << 8));
            std::memcpy(out + 2 * i, &v, 2);
        }
    }
    return true;
}

}  // namespace wul3d::detail
