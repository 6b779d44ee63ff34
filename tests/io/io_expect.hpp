#pragma once
// What the io tests share (images_test.cpp, sources_test.cpp): the check that a reader
// refuses quietly, and small images.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "wul3d/error.hpp"
#include "wul3d/image.hpp"

namespace wul3d::test {

namespace fs = std::filesystem;

inline bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

/// Runs `f`, expects an InputError whose message holds every one of `parts`, and nothing
/// printed on stderr (libpng and libjpeg must stay quiet: the CLI prints one line).
template <class F>
inline void expect_input_error(F&& f, const std::vector<std::string>& parts) {
    testing::internal::CaptureStderr();
    std::string msg;
    try {
        f();
    } catch (const wul3d::InputError& e) {
        msg = e.what();
    }
    const std::string err = testing::internal::GetCapturedStderr();
    ASSERT_FALSE(msg.empty()) << "no InputError";
    for (const auto& p : parts) EXPECT_TRUE(contains(msg, p)) << "'" << p << "' not in: " << msg;
    EXPECT_EQ(err, "") << "stderr was not quiet";
}

inline wul3d::DepthImage ramp_depth(int w, int h) {
    wul3d::DepthImage d;
    d.width = w;
    d.height = h;
    d.data.resize(static_cast<std::size_t>(w) * h);
    for (std::size_t p = 0; p < d.data.size(); ++p) d.data[p] = static_cast<std::uint16_t>(p * 997 % 65536);
    return d;
}

inline wul3d::ColorImage solid_color(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    wul3d::ColorImage c;
    c.width = w;
    c.height = h;
    c.rgb.resize(3 * static_cast<std::size_t>(w) * h);
    for (std::size_t p = 0; p < c.rgb.size(); p += 3) c.rgb[p] = r, c.rgb[p + 1] = g, c.rgb[p + 2] = b;
    return c;
}

inline void expect_no_temp_files(const fs::path& dir) {
    for (const auto& f : list_files(dir)) EXPECT_FALSE(contains(f, ".tmp-")) << f;
}

}  // namespace wul3d::test
