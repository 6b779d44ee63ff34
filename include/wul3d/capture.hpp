#pragma once
/// @file capture.hpp
/// Step 1 of the paper: colour and depth from a live camera, while the rest runs.
///
/// A `CameraDevice` is one opened camera (a backend: libfreenect, OpenNI2, and, when built
/// with them, libfreenect2 and librealsense2; docs/CAMERAS.md). It grabs synchronously.
/// A `LiveSource` runs a device on its own capture thread and hands frames to the processing
/// thread through a single-slot mailbox: when processing is slower than the camera the
/// newest frame wins and the overwritten one is counted as dropped, so memory never grows
/// and latency stays at one frame. Every wait has a timeout; nothing here can block forever.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "wul3d/io.hpp"
#include "wul3d/calibration.hpp"

namespace wul3d {

/// What one grab gave.
enum class GrabResult {
    Frame,    ///< a colour + depth pair is in the item
    Timeout,  ///< nothing within the timeout; try again
    End,      ///< a recording being replayed (an .oni file, a fakenect dump) has ended
};

/// One opened camera. Used from one thread at a time (the capture thread).
class CameraDevice {
public:
    virtual ~CameraDevice() = default;
    /// "Kinect v1 #0 (libfreenect)", for messages and summary.json.
    virtual std::string description() const = 0;
    /// Calibration of raw frames (the item's `raw`, registered by the pipeline with
    /// depth-to-color); nullptr when the device delivers registered frames (`frame`).
    virtual const StereoCalibration* calibration() const { return nullptr; }
    /// Waits up to `timeout` for the next colour + depth pair and puts it into `item`
    /// (buffers reused; the name is set by the caller). Throws DeviceLost when the camera
    /// is gone.
    virtual GrabResult grab(SourceItem& item, std::chrono::milliseconds timeout) = 0;
};

/// `--camera BACKEND[:ARG]`: "freenect", "freenect:1", "openni2", "openni2:file.oni",
/// "freenect2[:SERIAL]", "realsense[:SERIAL]".
struct CameraSpec {
    std::string backend;  ///< freenect | openni2 | freenect2 | realsense
    std::string arg;      ///< after the first ':', may be empty
    std::string text;     ///< as given
};
/// Throws ParamError for an unknown backend, naming the known ones.
CameraSpec parse_camera_spec(const std::string& text);
/// Backends compiled into this build, e.g. {"freenect", "openni2"}.
std::vector<std::string> camera_backends();
/// Opens the camera. Throws InputError (one line) when no camera is found, it is busy, its
/// mode is not supported, or the backend was not built in.
std::unique_ptr<CameraDevice> open_camera(const CameraSpec& spec);

struct LiveOptions {
    /// Capture waits for processing to take each frame instead of dropping it. Meant for
    /// replays (fakenect, .oni) and tests: a live camera's driver then drops frames itself.
    bool lossless = false;
    /// No frame for this long ends the capture with DeviceLost.
    std::chrono::milliseconds stall_timeout{5000};
};

/// A camera on its own capture thread, newest frame wins.
class LiveSource {
public:
    enum class Next { Frame, Timeout, End };

    /// Starts the capture thread.
    LiveSource(std::unique_ptr<CameraDevice> camera, const LiveOptions& options = {});
    ~LiveSource();  ///< stops and joins the capture thread
    LiveSource(const LiveSource&) = delete;
    LiveSource& operator=(const LiveSource&) = delete;

    /// Waits up to `timeout` for a frame not taken yet and swaps it into `item` (named
    /// frame_NNNNNN by capture order, so gaps in the names are the dropped frames). End once
    /// the device ended and every frame was taken. Rethrows the capture thread's error
    /// (DeviceLost, ...) once the frame captured before it was taken.
    Next next(SourceItem& item, std::chrono::milliseconds timeout);
    /// Stops capturing (idempotent); next() then returns what is left, then End.
    void stop();

    std::uint64_t captured() const { return captured_.load(); }  ///< frames grabbed
    std::uint64_t dropped() const { return dropped_.load(); }    ///< overwritten before taken
    const std::string& description() const { return description_; }
    const StereoCalibration* calibration() const { return calibration_; }

private:
    void capture_loop();

    std::unique_ptr<CameraDevice> camera_;
    LiveOptions options_;
    std::string description_;
    const StereoCalibration* calibration_ = nullptr;
    std::mutex mutex_;
    std::condition_variable cv_;
    SourceItem slot_;          // guarded by mutex_
    bool slot_full_ = false;   // guarded by mutex_
    bool ended_ = false;       // guarded by mutex_: no more frames will come
    std::exception_ptr error_; // guarded by mutex_
    std::atomic<bool> stop_{false};
    std::atomic<std::uint64_t> captured_{0}, dropped_{0};
    std::thread thread_;
};

}  // namespace wul3d
