# The installed package from outside (cmake/Install.cmake, examples/cpp): installs the built
# tree to a temporary prefix, configures and builds examples/cpp against that prefix alone,
# runs it on a shipped frame and checks its objects against what the installed `wul3d run`
# writes in objects.json for the same frame. Removes its folder however it ends.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DGENERATOR=... -DCXX=...
#         [-DLAUNCHER=ccache] [-DSANITIZE=address,undefined] -P install_test.cmake
cmake_minimum_required(VERSION 3.22)

macro(fail msg)
  file(REMOVE_RECURSE "${WORK_DIR}")
  message(FATAL_ERROR "${msg}")
endmacro()

macro(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err
                  TIMEOUT 500)
  if(NOT _rc EQUAL 0)
    fail("failed (${_rc}): ${ARGN}\n${_out}\n${_err}")
  endif()
endmacro()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
set(frame "${SOURCE_DIR}/data/samples/uois_tabletop/image_0000")

run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
foreach(f include/wul3d/pipeline.hpp include/wul3d/run.hpp lib/cmake/wul3d/wul3dConfig.cmake
          lib/cmake/wul3d/wul3dConfigVersion.cmake lib/cmake/wul3d/wul3dTargets.cmake bin/wul3d)
  if(NOT EXISTS "${prefix}/${f}")
    fail("not installed: ${f}")
  endif()
endforeach()

set(flags "")
if(SANITIZE)
  set(flags -DCMAKE_CXX_FLAGS=-fsanitize=${SANITIZE} -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZE})
endif()
if(LAUNCHER)
  list(APPEND flags -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/examples/cpp" -B "${WORK_DIR}/example" -G "${GENERATOR}"
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_EXPORT_COMPILE_COMMANDS=ON ${flags})
# Found in the prefix, and compiled with the installed headers, not the source tree's.
file(STRINGS "${WORK_DIR}/example/CMakeCache.txt" found REGEX "^wul3d_DIR:")
if(NOT found STREQUAL "wul3d_DIR:PATH=${prefix}/lib/cmake/wul3d")
  fail("example found wul3d elsewhere: ${found}")
endif()
run(${CMAKE_COMMAND} --build "${WORK_DIR}/example")
file(READ "${WORK_DIR}/example/compile_commands.json" commands)
string(FIND "${commands}" "${SOURCE_DIR}/include" in_tree)
string(FIND "${commands}" "${prefix}/include" in_prefix)
if(NOT in_tree EQUAL -1 OR in_prefix EQUAL -1)
  fail("example not compiled against the installed headers:\n${commands}")
endif()

run("${WORK_DIR}/example/wul3d_example" "${frame}")
set(printed "${_out}")
run("${prefix}/bin/wul3d" run "${frame}" -o "${WORK_DIR}/run" -q)
file(GLOB json "${WORK_DIR}/run/*/objects.json")
list(LENGTH json n_json)
if(NOT n_json EQUAL 1)
  fail("wul3d run wrote ${n_json} objects.json files")
endif()
file(READ "${json}" objects)
string(JSON n LENGTH "${objects}" objects)
if(n LESS 1)
  fail("no object in ${frame}: nothing to compare")
endif()
if(NOT printed MATCHES "image_0000: ${n} objects\n")
  fail("example printed another object count than wul3d run's ${n}:\n${printed}")
endif()
math(EXPR last "${n} - 1")
foreach(i RANGE ${last})
  foreach(key id pixels)
    string(JSON ${key} GET "${objects}" objects ${i} ${key})
  endforeach()
  foreach(key u_min v_min u_max v_max)
    string(JSON ${key} GET "${objects}" objects ${i} box_px ${key})
  endforeach()
  set(line "object ${id}: ${pixels} pixels, box ${u_min} ${v_min} ${u_max} ${v_max}, centroid")
  string(FIND "${printed}" "${line}" at)
  if(at EQUAL -1)
    fail("example did not print \"${line}\":\n${printed}")
  endif()
endforeach()
message(STATUS "example printed the ${n} objects of wul3d run")
file(REMOVE_RECURSE "${WORK_DIR}")
