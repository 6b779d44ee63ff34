#pragma once
// Private to src/capture/capture.cpp and src/capture/*.cpp: the camera backends. Each is compiled only
// when its library was found (CMakeLists.txt defines WUL3D_WITH_<NAME>); open_camera
// dispatches to them. `arg` is what follows "backend:" in --camera, possibly empty.
#include <memory>
#include <string>

#include "wul3d/capture.hpp"

namespace wul3d::detail {

std::unique_ptr<CameraDevice> open_freenect(const std::string& arg);   // capture_freenect.cpp
std::unique_ptr<CameraDevice> open_openni2(const std::string& arg);    // capture_openni2.cpp
std::unique_ptr<CameraDevice> open_freenect2(const std::string& arg);  // capture_freenect2.cpp
std::unique_ptr<CameraDevice> open_realsense(const std::string& arg);  // capture_realsense.cpp

}  // namespace wul3d::detail
