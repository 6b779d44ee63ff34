# The optional PCL peers; included from the top CMakeLists.txt before bench/ and eval/.
#   bench/pcl_normals_peer.cpp  wul3d_bench_pcl: PCL's integral-image normals (docs/BENCH.md)
#   eval/pcl_peers.cpp          wul3d_pcl_peers: PCL's plane RANSAC + Euclidean clustering and
#                               organized multi-plane + connected components (docs/PEERS.md)
# Sets WUL3D_PCL (ON/OFF) for both; with it, the target pcl_io serves the PCD reader's test
# against PCL's own writer (tests/io/pcl/pcd_writer_test.cpp) where it is found. PCL is not installed by scripts/install-deps.sh (Debian's
# libpcl-dev is some 312 packages): `apt-get install libpcl-dev`. Only the components the peers
# need are asked for, and only the top ones: PCLConfig leaves a component named before one that
# depends on it out of the dependant's link interface (asking for search before features
# made wul3d_bench_pcl miss libpcl_search at link time); segmentation brings search, kdtree
# and sample_consensus itself. PCL's features depend on its 2d module, which looks for VTK as an
# optional dependency; Debian's VTK 9 config then fails the generate step (VTK::mpi wants
# MPI::MPI_C) and costs seconds, so VTK is kept out of the search. Debian's PCL is built for
# generic x86-64: its translation units must not get -march=native or AVX flags (Eigen's
# alignment would differ from the library's), so the peers are skipped if the global flags
# carry any; nothing in this project adds such flags to a target.
option(WUL3D_WITH_PCL "Build the PCL peers (wul3d_bench_pcl, wul3d_pcl_peers) when PCL is found" ON)
set(WUL3D_PCL OFF)
if(WUL3D_WITH_PCL)
  set(CMAKE_DISABLE_FIND_PACKAGE_VTK TRUE)
  set(CMAKE_MESSAGE_LOG_LEVEL NOTICE)  # PCLConfig reports every module found, QUIET or not
  find_package(PCL 1.10 QUIET COMPONENTS common features segmentation)
  unset(CMAKE_MESSAGE_LOG_LEVEL)
  unset(CMAKE_DISABLE_FIND_PACKAGE_VTK)
  string(TOUPPER "${CMAKE_BUILD_TYPE}" _wul3d_config)
  set(_wul3d_global_flags "${CMAKE_CXX_FLAGS} ${CMAKE_CXX_FLAGS_${_wul3d_config}}")
  if(NOT PCL_FOUND OR NOT TARGET pcl_features OR NOT TARGET pcl_segmentation
     OR NOT TARGET pcl_sample_consensus OR NOT TARGET pcl_search OR NOT TARGET pcl_kdtree)
    message(STATUS "PCL not found: the PCL peers are skipped")
  elseif(_wul3d_global_flags MATCHES "-march=native|-march=x86-64-v[34]|-mavx|-mfma")
    message(STATUS "PCL found, but CMAKE_CXX_FLAGS carry -march/AVX flags that Debian's PCL "
                   "was not built with: the PCL peers are skipped")
  else()
    message(STATUS "PCL ${PCL_VERSION} found: building the PCL peers "
                   "(wul3d_bench_pcl with the benchmarks, wul3d_pcl_peers)")
    set(WUL3D_PCL ON)
    # PCL's own PCD writer for the PCD reader's test (tests/io/pcl/), asked for apart.
    set(CMAKE_DISABLE_FIND_PACKAGE_VTK TRUE)
    set(CMAKE_MESSAGE_LOG_LEVEL NOTICE)
    find_package(PCL 1.10 QUIET COMPONENTS io)
    unset(CMAKE_MESSAGE_LOG_LEVEL)
    unset(CMAKE_DISABLE_FIND_PACKAGE_VTK)
  endif()
else()
  message(STATUS "WUL3D_WITH_PCL is OFF: the PCL peers are skipped")
endif()
