#pragma once
// Memory for the images of wul3d.Result, reused from frame to frame. A fresh 640x480 result
// is 2.1 MB (labels, objects, colours); asked of the allocator each frame, it comes back as
// new pages that the kernel maps and zeroes on first write (about 0.5 ms a frame), and the
// previous result's pages are unmapped when Python drops it. Here each array's memory is a
// vector leased from its pipeline's pool: when the last numpy array on it is freed, the
// vector goes back to the pool, already mapped. With decimation (the default) the pipeline
// then writes the next frame's images into such vectors and hands them over without a copy
// (Pipeline::swap_images); at every pixel the result is copied into them.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace wul3d::python {

/// memcpy with streaming stores: the destination's lines are written whole, not read into
/// the cache first. A result's buffers were last touched frames ago and its 2.1 MB would not
/// stay in a core's cache anyway; written the usual way, each line is first fetched from
/// memory (as much traffic again as the copy), and the copy evicts the pipeline's own data.
/// bench/python/binding_overhead.py measures it (docs/PYTHON.md).
inline void copy_streaming(void* dst, const void* src, std::size_t bytes) {
#if defined(__SSE2__)
    auto* d = static_cast<unsigned char*>(dst);
    const auto* s = static_cast<const unsigned char*>(src);
    const auto misaligned = static_cast<std::size_t>(reinterpret_cast<std::uintptr_t>(d) % 16);
    const std::size_t head = std::min(bytes, misaligned ? 16 - misaligned : 0);
    std::memcpy(d, s, head);
    d += head;
    s += head;
    bytes -= head;
    const std::size_t lines = bytes / 64;  // four 16-byte stores fill a 64-byte line
    for (std::size_t i = 0; i < lines; ++i, d += 64, s += 64) {
        for (int k = 0; k < 4; ++k) {
            const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + 16 * k));
            _mm_stream_si128(reinterpret_cast<__m128i*>(d + 16 * k), v);
        }
    }
    _mm_sfence();  // the streamed stores are seen before anything after the copy
    std::memcpy(d, s, bytes - lines * 64);
#else
    std::memcpy(dst, src, bytes);
#endif
}

/// Vectors of T for the results' arrays, one pool per element type and pipeline.
template <class T>
class VectorPool : public std::enable_shared_from_this<VectorPool<T>> {
public:
    /// Vectors kept for reuse: two results' images (a loop that keeps the previous result
    /// while the next is made needs one result's worth); more are freed.
    static constexpr std::size_t kMaxFree = 4;

    /// A vector of n elements, its contents whatever they were: a free one of that size if
    /// there is one, else the newest free one resized, else a new one.
    std::vector<T> take(std::size_t n) {
        std::vector<T> v;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            std::size_t pick = free_.size();
            for (std::size_t i = free_.size(); i-- > 0;) {
                if (free_[i].size() == n) {
                    pick = i;
                    break;
                }
            }
            if (pick == free_.size() && !free_.empty()) pick = free_.size() - 1;
            if (pick < free_.size()) {
                v = std::move(free_[pick]);
                free_.erase(free_.begin() + static_cast<std::ptrdiff_t>(pick));
            }
        }
        v.resize(n);
        return v;
    }

    /// A C-contiguous array of `shape` on `v` (as many elements), which it owns: given back
    /// to the pool when Python frees the array, if the pool is still there (its pipeline
    /// alive), else freed.
    pybind11::array_t<T> array(std::vector<T>&& v, const std::vector<pybind11::ssize_t>& shape) {
        auto lease = std::make_unique<Lease>(this->weak_from_this(), std::move(v));
        T* data = lease->vector.data();
        pybind11::capsule owner(lease.get(), [](void* p) { delete static_cast<Lease*>(p); });
        lease.release();  // the capsule frees it from here on
        return pybind11::array_t<T>(shape, data, owner);
    }

    /// A vector back for reuse.
    void give_back(std::vector<T>&& v) {
        std::vector<T> dropped;  // the oldest, freed after the lock is released
        const std::lock_guard<std::mutex> lock(mutex_);
        if (free_.size() >= kMaxFree) {
            dropped = std::move(free_.front());
            free_.erase(free_.begin());
        }
        free_.push_back(std::move(v));
    }

    /// Vectors waiting for reuse (tests: results dropped give their memory back).
    std::size_t free_buffers() {
        const std::lock_guard<std::mutex> lock(mutex_);
        return free_.size();
    }

private:
    struct Lease {
        Lease(std::weak_ptr<VectorPool> p, std::vector<T>&& v) : pool(std::move(p)), vector(std::move(v)) {}
        ~Lease() {
            if (const std::shared_ptr<VectorPool> p = pool.lock()) p->give_back(std::move(vector));
        }
        Lease(const Lease&) = delete;
        Lease& operator=(const Lease&) = delete;
        std::weak_ptr<VectorPool> pool;
        std::vector<T> vector;
    };

    std::mutex mutex_;
    std::vector<std::vector<T>> free_;
};

/// A pipeline's pools: 16-bit labels (labels, objects) and 8-bit colours.
struct ResultPools {
    std::shared_ptr<VectorPool<std::uint16_t>> labels = std::make_shared<VectorPool<std::uint16_t>>();
    std::shared_ptr<VectorPool<std::uint8_t>> rgb = std::make_shared<VectorPool<std::uint8_t>>();
};

}  // namespace wul3d::python
