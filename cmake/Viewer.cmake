# What `wul3d view` and `wul3d run --video` need; included from the top CMakeLists.txt after
# the wul3d_cli target and the tests are defined.
#
# The viewer (apps/wul3d/view_command.cpp, apps/wul3d/viewer_*.cpp) is built only when GLFW 3,
# OpenGL and Dear ImGui (Debian: libglfw3-dev, libgl-dev, libimgui-dev; the latter ships the
# GLFW and OpenGL 3 backends inside libimgui.a) are found. Otherwise those files leave the
# target and apps/wul3d/view_unavailable.cpp stands in: `wul3d view` then says "built without
# viewer support" and exits 2. WUL3D_VIEWER tells which (ON/OFF).
# The video (apps/wul3d/video_writer.cpp) always builds: OpenCV's videoio, FFmpeg backend.

find_package(PkgConfig QUIET)
find_package(OpenGL QUIET COMPONENTS OpenGL)
if(PkgConfig_FOUND)
  pkg_check_modules(WUL3D_GLFW3 QUIET IMPORTED_TARGET glfw3>=3.3)
  pkg_check_modules(WUL3D_IMGUI QUIET IMPORTED_TARGET imgui)
endif()

set(_viewer_dir ${PROJECT_SOURCE_DIR}/apps/wul3d)
file(GLOB _viewer_sources CONFIGURE_DEPENDS ${_viewer_dir}/view_command.cpp ${_viewer_dir}/viewer_*.cpp)
get_target_property(_cli_sources wul3d_cli SOURCES)

if(WUL3D_GLFW3_FOUND AND WUL3D_IMGUI_FOUND AND TARGET OpenGL::GL)
  set(WUL3D_VIEWER ON)
  list(REMOVE_ITEM _cli_sources ${_viewer_dir}/view_unavailable.cpp)
  target_link_libraries(wul3d_cli PRIVATE PkgConfig::WUL3D_GLFW3 PkgConfig::WUL3D_IMGUI OpenGL::GL)
  message(STATUS "wul3d view: GLFW ${WUL3D_GLFW3_VERSION}, Dear ImGui ${WUL3D_IMGUI_VERSION}, OpenGL")
else()
  set(WUL3D_VIEWER OFF)
  list(REMOVE_ITEM _cli_sources ${_viewer_sources})
  message(STATUS "wul3d view: not built (needs GLFW 3, OpenGL and Dear ImGui: "
                 "libglfw3-dev libgl-dev libimgui-dev)")
endif()
set_target_properties(wul3d_cli PROPERTIES SOURCES "${_cli_sources}")

# Video export: OpenCV's VideoWriter (FFmpeg) and putText for the burned-in captions.
target_link_libraries(wul3d_cli PRIVATE opencv_core opencv_imgproc opencv_videoio)
target_include_directories(wul3d_cli SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})

# Their tests: view_test learns whether the viewer was built; video_test reads the video
# back with OpenCV's VideoCapture.
if(TARGET view_test)
  if(WUL3D_VIEWER)
    target_compile_definitions(view_test PRIVATE WUL3D_VIEWER_BUILT=1)
  else()
    target_compile_definitions(view_test PRIVATE WUL3D_VIEWER_BUILT=0)
  endif()
endif()
if(TARGET video_test)
  target_link_libraries(video_test PRIVATE opencv_core opencv_videoio)
  target_include_directories(video_test SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
endif()
