#pragma once
// Memory for the images of wul3d.Result, reused from frame to frame. A fresh 640x480 result
// is 2.1 MB (labels, objects, colours); asked of the allocator each frame, it comes back as
// new pages that the kernel maps and zeroes on first write (about 0.5 ms a frame), and the
// previous result's pages are unmapped when Python drops it. Here each array's memory is a
// buffer leased from its pipeline's pool: when the last numpy array on it is freed, the
// buffer goes back to the pool, already mapped, and the next result is copied into it.
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

class BufferPool : public std::enable_shared_from_this<BufferPool> {
public:
    /// Buffers kept for reuse: two results' images (a loop that keeps the previous result
    /// while the next is made needs one result's worth); more are freed.
    static constexpr std::size_t kMaxFree = 6;

    /// A C-contiguous array of `shape` on a leased buffer, its contents not initialised. The
    /// array owns the lease: it stays valid as long as Python holds it, after the pool too.
    template <class T>
    pybind11::array_t<T> array(const std::vector<pybind11::ssize_t>& shape) {
        std::size_t n = 1;
        for (const pybind11::ssize_t d : shape) n *= static_cast<std::size_t>(d);
        auto lease = std::make_unique<Lease>(weak_from_this(), take(n * sizeof(T)));
        T* data = reinterpret_cast<T*>(lease->buffer.data.get());
        pybind11::capsule owner(lease.get(), [](void* p) { delete static_cast<Lease*>(p); });
        lease.release();  // the capsule frees it from here on
        return pybind11::array_t<T>(shape, data, owner);
    }

    /// Buffers waiting for reuse (tests: results dropped give their memory back).
    std::size_t free_buffers() {
        const std::lock_guard<std::mutex> lock(mutex_);
        return free_.size();
    }

private:
    struct Buffer {
        std::unique_ptr<std::byte[]> data;
        std::size_t bytes = 0;
    };

    /// One array's buffer; given back to the pool when the array is freed, if the pool is
    /// still there (its pipeline alive), else freed.
    struct Lease {
        Lease(std::weak_ptr<BufferPool> p, Buffer b) : pool(std::move(p)), buffer(std::move(b)) {}
        ~Lease() {
            if (const std::shared_ptr<BufferPool> p = pool.lock()) p->give_back(std::move(buffer));
        }
        Lease(const Lease&) = delete;
        Lease& operator=(const Lease&) = delete;
        std::weak_ptr<BufferPool> pool;
        Buffer buffer;
    };

    Buffer take(std::size_t bytes) {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            for (std::size_t i = free_.size(); i-- > 0;) {
                if (free_[i].bytes != bytes) continue;
                Buffer b = std::move(free_[i]);
                free_.erase(free_.begin() + static_cast<std::ptrdiff_t>(i));
                return b;
            }
        }
        return Buffer{std::unique_ptr<std::byte[]>(new std::byte[bytes == 0 ? 1 : bytes]), bytes};
    }

    void give_back(Buffer b) {
        Buffer dropped;  // the oldest, freed after the lock is released
        const std::lock_guard<std::mutex> lock(mutex_);
        if (free_.size() >= kMaxFree) {
            dropped = std::move(free_.front());
            free_.erase(free_.begin());
        }
        free_.push_back(std::move(b));
    }

    std::mutex mutex_;
    std::vector<Buffer> free_;
};

}  // namespace wul3d::python
