# ROS 1 (docs/ROS.md; docs/INPUTS.md, "4. ROS bags"); included from the top CMakeLists.txt
# after the wul3d library target is defined. Debian 12 ships ROS 1 (Noetic-era) libraries;
# ROS 2 is not packaged there and not supported yet.
#
#   bags      src/bag/bag_source.cpp    librosbag_storage      Debian: librosbag-dev
#   wul3d_ros apps/wul3d_ros/main.cpp   roscpp, message_filters Debian: libroscpp-dev,
#             (and tests/ros/)          + message headers       libmessage-filters-dev, ...
# Without them the library is built with src/bag/bag_unavailable.cpp, which refuses bags with
# one line, and wul3d_ros is not built. Debian's rosbag_storage.pc cannot be used (it requires
# a pluginlib.pc that its ROS 2 pluginlib lacks), so the bag libraries are found one by one;
# rosbag/bag.h includes that ROS 2 pluginlib, whose headers live in per-package folders.
# ROS 1's message headers do not compile as C++20 (std::allocator<void>::rebind), so the
# files that include them are compiled as C++17.
option(WUL3D_WITH_ROS "Build the ROS 1 bag reader and node where ROS is found" ON)
find_package(PkgConfig QUIET)
set(WUL3D_ROS_BAGS OFF)
set(WUL3D_ROS_NODE OFF)

set(_ros_libs "")
foreach(_lib rosbag_storage roslz4 roscpp_serialization rostime cpp_common console_bridge
             boost_filesystem)
  find_library(WUL3D_LIB_${_lib} ${_lib})
  if(WUL3D_LIB_${_lib})
    list(APPEND _ros_libs ${WUL3D_LIB_${_lib}})
  else()
    set(_ros_missing "lib${_lib}")
  endif()
endforeach()
find_path(WUL3D_ROSBAG_INCLUDE rosbag/bag.h)
find_path(WUL3D_SENSOR_MSGS_INCLUDE sensor_msgs/Image.h)
set(_ros_includes "")
foreach(_pkg pluginlib class_loader rcpputils rcutils ament_index_cpp)
  if(EXISTS /usr/include/${_pkg}/${_pkg})
    list(APPEND _ros_includes /usr/include/${_pkg})
  elseif(NOT EXISTS /usr/include/${_pkg})
    set(_ros_missing "${_pkg} headers")
  endif()
endforeach()
if(NOT WUL3D_ROSBAG_INCLUDE OR NOT WUL3D_SENSOR_MSGS_INCLUDE)
  set(_ros_missing "rosbag/bag.h or sensor_msgs/Image.h")
endif()
if(NOT WUL3D_WITH_ROS)
  set(_ros_missing "WUL3D_WITH_ROS=OFF")
endif()

if(NOT _ros_missing)
  set(WUL3D_ROS_BAGS ON)
  set(WUL3D_ROS_INCLUDES ${_ros_includes})
  set(WUL3D_ROS_BAG_LIBS ${_ros_libs})
  target_sources(wul3d PRIVATE ${PROJECT_SOURCE_DIR}/src/bag/bag_source.cpp)
  set_source_files_properties(${PROJECT_SOURCE_DIR}/src/bag/bag_source.cpp
                              PROPERTIES COMPILE_OPTIONS "-std=c++17")
  target_include_directories(wul3d SYSTEM PRIVATE ${_ros_includes})
  target_link_libraries(wul3d PRIVATE ${_ros_libs})
  message(STATUS "wul3d ROS bags: on (librosbag_storage)")
else()
  target_sources(wul3d PRIVATE ${PROJECT_SOURCE_DIR}/src/bag/bag_unavailable.cpp)
  if(WUL3D_WITH_ROS)
    message(STATUS "wul3d ROS bags: off (${_ros_missing} not found; Debian: librosbag-dev)")
  else()
    message(STATUS "wul3d ROS bags: off (WUL3D_WITH_ROS=OFF)")
  endif()
endif()
if(WUL3D_ROS_BAGS AND PkgConfig_FOUND)
  pkg_check_modules(WUL3D_PC_ROSCPP QUIET IMPORTED_TARGET roscpp message_filters)
endif()
find_path(WUL3D_VISUALIZATION_MSGS_INCLUDE visualization_msgs/MarkerArray.h)
find_path(WUL3D_DIAGNOSTIC_MSGS_INCLUDE diagnostic_msgs/DiagnosticArray.h)
if(WUL3D_PC_ROSCPP_FOUND AND WUL3D_VISUALIZATION_MSGS_INCLUDE AND WUL3D_DIAGNOSTIC_MSGS_INCLUDE)
  set(WUL3D_ROS_NODE ON)
  add_executable(wul3d_ros ${PROJECT_SOURCE_DIR}/apps/wul3d_ros/main.cpp)
  set_target_properties(wul3d_ros PROPERTIES CXX_STANDARD 17)
  target_include_directories(wul3d_ros SYSTEM PRIVATE ${_ros_includes})
  target_link_libraries(wul3d_ros PRIVATE wul3d PkgConfig::WUL3D_PC_ROSCPP
                        nlohmann_json::nlohmann_json)
  target_compile_options(wul3d_ros PRIVATE ${WUL3D_WARNINGS})
  # A ROS package for roslaunch (apps/wul3d_ros/wul3d.launch): ROS_PACKAGE_PATH=build/ros.
  set(_pkg ${PROJECT_BINARY_DIR}/ros/wul3d_ros)
  configure_file(${PROJECT_SOURCE_DIR}/apps/wul3d_ros/package.xml ${_pkg}/package.xml COPYONLY)
  add_custom_command(TARGET wul3d_ros POST_BUILD
    COMMAND ${CMAKE_COMMAND} -E create_symlink $<TARGET_FILE:wul3d_ros> ${_pkg}/wul3d_ros)
  message(STATUS "wul3d ROS node: on (wul3d_ros)")
elseif(NOT WUL3D_ROS_BAGS)
  message(STATUS "wul3d ROS node: off (as the ROS bags)")
else()
  message(STATUS "wul3d ROS node: off (roscpp, message_filters, visualization_msgs or "
                 "diagnostic_msgs not found; Debian: libroscpp-dev libmessage-filters-dev "
                 "libvisualization-msgs-dev libdiagnostic-msgs-dev)")
endif()
