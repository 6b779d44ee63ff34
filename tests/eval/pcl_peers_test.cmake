# PclPeers.FindObjectsAndLeaveTheTableOut (registered by eval/CMakeLists.txt when PCL is found):
# wul3d_pcl_peers, both methods, on two shipped tabletop frames that show at least 3 objects
# each on a table that fills most of the view. Each method must write objects.png and find
# 3 to 60 objects, none larger than 20 % of the pixels with depth: the table (about two thirds
# of them in uois_tabletop/image_0000) must be left out, not made an object. Fails when the
# plane is not removed, e.g. with PCL >= 1.10's comparator given the plane labels as the
# demo's older API wanted (the table is then the one object found).
# cmake -DPROGRAM=... -DSAMPLES=data/samples -DWORK_DIR=... -P pcl_peers_test.cmake
foreach(var PROGRAM SAMPLES WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "pcl_peers_test.cmake: -D${var}= is missing")
  endif()
endforeach()

set(frames uois_tabletop/image_0000 pcl_kinect/milk_cartoon_all_small_clorox)
foreach(method plane-euclidean organized)
  foreach(frame ${frames})
    get_filename_component(name ${frame} NAME)
    set(out ${WORK_DIR}/${method}-${name})
    file(REMOVE_RECURSE ${out})
    execute_process(COMMAND ${PROGRAM} --method ${method} ${SAMPLES}/${frame} ${out}
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${method} on ${frame}: exit ${rc}: ${err}")
    endif()
    if(NOT EXISTS ${out}/${name}/objects.png)
      message(FATAL_ERROR "${method} on ${frame}: ${out}/${name}/objects.png not written")
    endif()
    file(READ ${out}/summary.json summary)
    string(JSON objects GET "${summary}" frames 0 objects)
    string(JSON depth_pixels GET "${summary}" frames 0 depth_pixels)
    if(objects LESS 3 OR objects GREATER 60)
      message(FATAL_ERROR "${method} on ${frame}: ${objects} objects, expected 3 to 60")
    endif()
    math(EXPR last "${objects} - 1")
    set(largest 0)
    foreach(i RANGE ${last})
      string(JSON px GET "${summary}" frames 0 object_pixels ${i})
      if(px GREATER largest)
        set(largest ${px})
      endif()
    endforeach()
    math(EXPR percent "100 * ${largest} / ${depth_pixels}")
    if(percent GREATER_EQUAL 20)
      message(FATAL_ERROR "${method} on ${frame}: an object of ${largest} pixels, ${percent} % of "
                          "the ${depth_pixels} with depth: the table was not left out")
    endif()
    message(STATUS "${method} on ${frame}: ${objects} objects, the largest ${percent} % of the "
                   "pixels with depth")
  endforeach()
endforeach()
