# What `wul3d view` and `wul3d run --video` need; included from the top CMakeLists.txt after
# the wul3d_cli target and the tests are defined.
#
# The viewer (apps/wul3d/view_command.cpp, apps/wul3d/viewer_*.cpp) is built only when GLFW 3,
# OpenGL and Dear ImGui (Debian: libglfw3-dev, libgl-dev, libimgui-dev; the latter ships the
# GLFW and OpenGL 3 backends inside libimgui.a) are found. Otherwise those files leave the
# target and apps/wul3d/view_unavailable.cpp stands in: `wul3d view` then says "built without
# viewer support" and exits 2. WUL3D_VIEWER tells which (ON/OFF).
# The video always builds: apps/wul3d/video_writer.cpp draws the panels and captions (OpenCV
# core and imgproc, in wul3d); apps/wul3d/video_plugin.cpp is the module libwul3d_video.so,
# the only target that links OpenCV's videoio (FFmpeg backend). wul3d loads it with dlopen
# from its own folder for `run --video` alone: videoio maps FFmpeg and GStreamer, about 17 MB
# of memory at start that every other wul3d process (bench's peak memory included) would
# carry for nothing. Building wul3d builds the plugin next to it.

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
list(REMOVE_ITEM _cli_sources ${_viewer_dir}/video_plugin.cpp)  # the plugin's, below
set_target_properties(wul3d_cli PROPERTIES SOURCES "${_cli_sources}")

# Video export: panels and putText captions in wul3d (core, imgproc); OpenCV's VideoWriter
# (FFmpeg) in the plugin, written beside the wul3d executable, where wul3d looks for it.
add_library(wul3d_video MODULE ${_viewer_dir}/video_plugin.cpp)
get_target_property(_cli_dir wul3d_cli RUNTIME_OUTPUT_DIRECTORY)
if(NOT _cli_dir)
  get_target_property(_cli_dir wul3d_cli BINARY_DIR)
endif()
set_target_properties(wul3d_video PROPERTIES
  LIBRARY_OUTPUT_DIRECTORY ${_cli_dir}
  CXX_VISIBILITY_PRESET hidden
  VISIBILITY_INLINES_HIDDEN ON)
target_link_libraries(wul3d_video PRIVATE opencv_core opencv_videoio)
target_include_directories(wul3d_video SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_compile_options(wul3d_video PRIVATE ${WUL3D_WARNINGS})

target_link_libraries(wul3d_cli PRIVATE opencv_core opencv_imgproc ${CMAKE_DL_LIBS})
target_include_directories(wul3d_cli SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
target_compile_definitions(wul3d_cli PRIVATE
  WUL3D_VIDEO_PLUGIN_FILE="$<TARGET_FILE_NAME:wul3d_video>")
add_dependencies(wul3d_cli wul3d_video)

# Their tests: view_test learns whether the viewer was built; video_test reads the video
# back with OpenCV's VideoCapture and knows where the plugin is.
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
  target_compile_definitions(video_test PRIVATE WUL3D_VIDEO_PLUGIN="$<TARGET_FILE:wul3d_video>")
endif()
