#pragma once
// The C interface between `wul3d` and its video plugin (libwul3d_video.so, built from
// video_plugin.cpp next to the wul3d executable). Only the plugin links OpenCV's videoio,
// which pulls FFmpeg and GStreamer (about 17 MB of memory at start); wul3d loads it with
// dlopen when `run --video` is used, the way OpenCV loads its own videoio backends.
//
// One exported symbol, wul3d_video_api(version): the table below, or a null pointer when
// the plugin does not speak that version. A change to the table bumps the version.
#include <cstddef>

#define WUL3D_VIDEO_API_VERSION 1
#define WUL3D_VIDEO_API_SYMBOL "wul3d_video_api"

extern "C" {

struct Wul3dVideoApi {
    int version;  ///< WUL3D_VIDEO_API_VERSION of the plugin

    /// Opens a video writer on `path` (FFmpeg picks the container from the extension) with
    /// the codec `fourcc` (4 characters, e.g. "avc1"), `fps` frames per second, frames of
    /// width x height BGR pixels. A handle, or null (see last_error).
    void* (*open)(const char* path, const char* fourcc, double fps, int width, int height);
    /// Appends one frame of the opened size: `bgr` rows `stride` bytes apart. 0 on success.
    int (*write)(void* writer, const unsigned char* bgr, std::size_t stride);
    /// Finishes the file and frees the handle (null: nothing). 0 on success.
    int (*close)(void* writer);
    /// One line about this thread's last failed call ("" if none).
    const char* (*last_error)();
};

/// The entry point: the table if the plugin speaks `version`, else null.
using Wul3dVideoApiEntry = const Wul3dVideoApi* (*)(int version);

}  // extern "C"
