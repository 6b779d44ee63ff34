# Live cameras (include/wul3d/capture.hpp, docs/CAMERAS.md); included from the top
# CMakeLists.txt after the wul3d library target is defined.
#
# Each backend in src/capture/ is compiled only when its library is found through
# pkg-config, and then defines WUL3D_WITH_<NAME> for src/capture/capture.cpp. A backend that is not
# built makes `--camera NAME` say so and exit 2.
#   freenect   Kinect v1, libfreenect     Debian: libfreenect-dev (fakenect: libfreenect-bin)
#   openni2    OpenNI2 devices, .oni      Debian: libopenni2-dev
#   freenect2  Kinect v2, libfreenect2    not in Debian 12: build it from source (freenect2.pc)
#   realsense  RealSense, librealsense2   not in Debian 12: Intel's packages or source (realsense2.pc)
find_package(Threads REQUIRED)
find_package(PkgConfig QUIET)
target_link_libraries(wul3d PRIVATE Threads::Threads)

set(_capture_dir ${PROJECT_SOURCE_DIR}/src/capture)
set(WUL3D_CAMERAS "")
set(WUL3D_CAMERA_MODULES "")
macro(wul3d_camera_backend name define module source)
  if(PkgConfig_FOUND)
    pkg_check_modules(WUL3D_PC_${define} QUIET IMPORTED_TARGET ${module})
  endif()
  if(WUL3D_PC_${define}_FOUND)
    target_sources(wul3d PRIVATE ${_capture_dir}/${source})
    target_link_libraries(wul3d PRIVATE PkgConfig::WUL3D_PC_${define})
    target_compile_definitions(wul3d PRIVATE WUL3D_WITH_${define}=1)
    list(APPEND WUL3D_CAMERAS ${name})
    list(APPEND WUL3D_CAMERA_MODULES "${define}=${module}")  # for wul3dConfig.cmake
  endif()
endmacro()
wul3d_camera_backend(freenect FREENECT libfreenect capture_freenect.cpp)
wul3d_camera_backend(openni2 OPENNI2 libopenni2 capture_openni2.cpp)
wul3d_camera_backend(freenect2 FREENECT2 freenect2 capture_freenect2.cpp)
wul3d_camera_backend(realsense REALSENSE realsense2 capture_realsense.cpp)
message(STATUS "wul3d cameras: ${WUL3D_CAMERAS} (of freenect openni2 freenect2 realsense)")
