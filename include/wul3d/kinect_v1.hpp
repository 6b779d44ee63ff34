#pragma once
/// @file kinect_v1.hpp
/// The Kinect v1's depth model, used both ways: raw 11-bit disparity -> millimetres when
/// capturing through libfreenect (capture.hpp), millimetres -> raw disparity when writing a
/// recording as a fakenect dump (export-fakenect), so that a replay goes through exactly the
/// path a live Kinect v1 takes. Sources and the measured round-trip error: docs/CAMERAS.md.
///
/// Disparity model (N. Burrus, "Kinect calibration", 2011, as quoted on the OpenKinect wiki,
/// "Imaging Information"): z_m = 1 / (kA * d + kB) with kA = -0.0030711016 and
/// kB = 3.3309495161, d the raw 11-bit value; d = 2047 means "no reading". Inverse:
/// d = (1 / z_m - kB) / kA, rounded to the nearest integer.
///
/// Stereo model: the depth image lies in the IR camera (640x480, Burrus's IR intrinsics), the
/// colour image in the RGB camera (640x480, Burrus's RGB intrinsics); P_rgb = R P_ir + t with
/// Burrus's R and t (about 2 cm between the two cameras). Lens distortion is ignored.
#include <cstdint>
#include <string>
#include <vector>

#include "wul3d/frame.hpp"
#include "wul3d/registration.hpp"

namespace wul3d {

constexpr int kKinectV1Width = 640;   ///< both cameras, FREENECT_RESOLUTION_MEDIUM
constexpr int kKinectV1Height = 480;
constexpr std::uint16_t kKinectV1NoDepth = 2047;  ///< raw value of "no reading"
constexpr double kKinectV1DispA = -0.0030711016;  ///< 1/m per raw unit (Burrus)
constexpr double kKinectV1DispB = 3.3309495161;   ///< 1/m (Burrus)
/// Largest raw value converted to a depth: 1 / (kA d + kB) grows without bound near
/// d = 1084; above 1050 (about 9.4 m, beyond the sensor's range) a reading is treated as none.
constexpr std::uint16_t kKinectV1MaxRaw = 1050;

/// Raw 11-bit disparity to metres; 0 for "no reading" (2047) or a value above kKinectV1MaxRaw.
double kinect_v1_raw_to_m(std::uint16_t raw);
/// Metres to the nearest raw disparity; kKinectV1NoDepth for z <= 0, not finite, or outside
/// [kinect_v1_raw_to_m(0), kinect_v1_raw_to_m(kKinectV1MaxRaw)] (about 0.30-9.4 m).
std::uint16_t kinect_v1_m_to_raw(double z_m);
/// Depth step between neighbouring raw values at depth z (metres): |dz/dd| = -kA z^2.
/// 0.8 mm at 0.5 m, 3.1 mm at 1 m, 12 mm at 2 m, 49 mm at 4 m.
double kinect_v1_step_m(double z_m);

/// IR (depth) and RGB cameras of a Kinect v1 and the IR -> RGB extrinsic (Burrus), depth in
/// millimetres. Registration with it (register_depth_to_color) gives depth in the RGB camera.
StereoCalibration kinect_v1_calibration();

/// Converts a raw 11-bit depth image (640x480, as libfreenect's FREENECT_DEPTH_11BIT
/// delivers it) to millimetres in the depth (IR) camera, 0 where there is no reading.
/// `out` is resized only when its size changes. Table lookup, no allocation per frame.
void kinect_v1_raw_to_depth(const std::uint16_t* raw, DepthImage& out);

/// The inverse of capture: a registered frame (depth in the RGB camera, the layout of
/// frame folders) moved back into the IR camera with the same stereo model (z-buffer splat
/// with the inverse extrinsic; nearest surface wins) and converted to raw disparity, 2047
/// where the IR camera gets no depth. `depth` must be 640x480. `raw` gets 640 * 480 values.
void kinect_v1_depth_to_raw(const DepthImage& depth, RegistrationWorkspace& ws,
                            std::vector<std::uint16_t>& raw);

/// Writes a fakenect dump (the layout fakenect-record(1) writes and fakenect(1) replays):
/// DIR/INDEX.txt listing, in time order, `r-<seconds>-<timestamp>.ppm` (a one-line "P6 640
/// 480 255" header, then 640x480 RGB bytes) and `d-<seconds>-<timestamp>.pgm` (a one-line
/// "P5 640 480 65535" header, then 640x480 raw 11-bit values as little-endian uint16, the
/// bytes libfreenect's depth callback receives; not a standard big-endian PGM).
class FakenectDumpWriter {
public:
    /// Writes into a new temporary folder beside `dir`, which finish() renames to `dir`
    /// (which must not exist or be an empty folder): the dump is complete or absent. Throws
    /// IoError.
    explicit FakenectDumpWriter(const std::string& dir, double fps = 30.0);
    /// Without finish(), removes the files it wrote and its temporary folder.
    ~FakenectDumpWriter();
    FakenectDumpWriter(const FakenectDumpWriter&) = delete;
    FakenectDumpWriter& operator=(const FakenectDumpWriter&) = delete;
    /// Appends one frame: colour first, then depth 1 ms later, both at frame time i / fps.
    /// Throws InputError if `color` is not 640x480 or `raw_depth` has not 640 * 480 values.
    void add(const ColorImage& color, const std::vector<std::uint16_t>& raw_depth);
    /// Writes INDEX.txt and renames the folder to `dir`. Without it fakenect has nothing to
    /// replay.
    void finish();
    std::size_t frames() const { return frames_; }

private:
    std::string dir_;
    std::string tmp_;  ///< where the files go until finish()
    bool finished_ = false;
    double fps_;
    std::size_t frames_ = 0;
    std::vector<std::string> index_;
};

}  // namespace wul3d
