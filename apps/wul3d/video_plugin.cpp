// libwul3d_video.so: OpenCV's VideoWriter (FFmpeg backend) behind the C table of
// video_plugin.hpp. Built as a module next to the wul3d executable, which loads it with
// dlopen only for `run --video`, so that no other wul3d process maps videoio and FFmpeg.
// No C++ exception leaves this file: failures are return values and last_error().
#include "video_plugin.hpp"

#include <exception>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

namespace {

thread_local std::string last_error_text;

struct Writer {
    cv::VideoWriter writer;
    cv::Size size;
};

void* open_writer(const char* path, const char* fourcc, double fps, int width, int height) {
    last_error_text.clear();
    try {
        if (!path || !fourcc || std::char_traits<char>::length(fourcc) != 4 || width <= 0 ||
            height <= 0 || !(fps > 0)) {
            last_error_text = "bad arguments to open";
            return nullptr;
        }
        auto w = std::make_unique<Writer>();
        w->size = cv::Size(width, height);
        const int code = cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]);
        if (w->writer.open(path, cv::CAP_FFMPEG, code, fps, w->size)) return w.release();
        last_error_text = std::string("FFmpeg cannot write ") + fourcc + " to " + path;
    } catch (const std::exception& e) {
        last_error_text = e.what();
    }
    return nullptr;
}

int write_frame(void* writer, const unsigned char* bgr, std::size_t stride) {
    last_error_text.clear();
    try {
        auto* w = static_cast<Writer*>(writer);
        if (!w || !bgr) {
            last_error_text = "bad arguments to write";
            return 1;
        }
        const cv::Mat frame(w->size, CV_8UC3, const_cast<unsigned char*>(bgr), stride);
        w->writer.write(frame);
        return 0;
    } catch (const std::exception& e) {
        last_error_text = e.what();
        return 1;
    }
}

int close_writer(void* writer) {
    last_error_text.clear();
    auto* w = static_cast<Writer*>(writer);
    int status = 0;
    try {
        if (w) w->writer.release();
    } catch (const std::exception& e) {
        last_error_text = e.what();
        status = 1;
    }
    delete w;
    return status;
}

const char* last_error() { return last_error_text.c_str(); }

constexpr Wul3dVideoApi kApi = {WUL3D_VIDEO_API_VERSION, open_writer, write_frame, close_writer,
                                last_error};

}  // namespace

extern "C" __attribute__((visibility("default"))) const Wul3dVideoApi* wul3d_video_api(
    int version) {
    return version == WUL3D_VIDEO_API_VERSION ? &kApi : nullptr;
}
