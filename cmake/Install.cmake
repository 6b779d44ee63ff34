# `cmake --install build [--prefix P]`: the package a consumer finds with
#   find_package(wul3d 0.2 REQUIRED)  ->  target wul3d::wul3d
# (docs/LIBRARY.md, examples/cpp/). Installs include/wul3d/, the library, the exported target
# and its config and version files under lib/cmake/wul3d/, and the command with its video
# plugin in bin/ (the command looks for the plugin beside itself).
#
# The library is static by default (-DBUILD_SHARED_LIBS=ON makes it shared: untested). A static
# library's private dependencies (OpenCV core/imgproc, libpng, libjpeg, threads, the camera
# backends) are still needed when the consumer links, so wul3dConfig.cmake finds them again;
# a shared library needs only its public one, OpenMP.
include(CMakePackageConfigHelpers)
set(WUL3D_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/wul3d)

install(TARGETS wul3d EXPORT wul3dTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/wul3d DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${PROJECT_BINARY_DIR}/include/wul3d/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/wul3d)  # generated: WUL3D_VERSION
install(EXPORT wul3dTargets NAMESPACE wul3d:: DESTINATION ${WUL3D_CMAKE_DIR})

get_target_property(_wul3d_type wul3d TYPE)
if(_wul3d_type STREQUAL "STATIC_LIBRARY")
  set(WUL3D_STATIC ON)
else()
  set(WUL3D_STATIC OFF)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/wul3dConfig.cmake.in
  ${PROJECT_BINARY_DIR}/wul3dConfig.cmake INSTALL_DESTINATION ${WUL3D_CMAKE_DIR})
# Before 1.0 a minor version may change the API: 0.2 is compatible with 0.2.x only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/wul3dConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/wul3dConfig.cmake ${PROJECT_BINARY_DIR}/wul3dConfigVersion.cmake
  DESTINATION ${WUL3D_CMAKE_DIR})

set_target_properties(wul3d_cli PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
install(TARGETS wul3d_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET wul3d_video)
  install(TARGETS wul3d_video LIBRARY DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
