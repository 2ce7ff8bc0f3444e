# haze render's arguments refused before anything is written (issue 26): --out other than an EXR,
# --out naming the scene itself (left unchanged), and a reference shortcut given twice (--spp and
# --set spp). Arguments: -DHAZE (the command) -DSOURCE_DIR -DWORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
file(COPY ${SOURCE_DIR}/examples/homogeneous_fog.json DESTINATION ${WORK_DIR})
set(scene ${WORK_DIR}/homogeneous_fog.json)
file(COPY_FILE ${scene} ${WORK_DIR}/scene.exr)

# refused(<expected text> args...): haze exits non-zero and says the text on stderr.
function(refused expected)
  execute_process(COMMAND ${HAZE} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0)
    message(FATAL_ERROR "accepted: haze ${ARGN}\n${out}")
  endif()
  string(FIND "${err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "haze ${ARGN}: expected \"${expected}\" in:\n${err}")
  endif()
endfunction()

refused("--out: got ${WORK_DIR}/x.png, expected an .exr file name" render ${scene} --out ${WORK_DIR}/x.png)
if(EXISTS ${WORK_DIR}/x.png)
  message(FATAL_ERROR "--out x.png still wrote x.png")
endif()
file(SHA256 ${WORK_DIR}/scene.exr before)
refused("expected a file other than the scene" render ${WORK_DIR}/scene.exr --out ${WORK_DIR}/scene.exr)
file(SHA256 ${WORK_DIR}/scene.exr after)
if(NOT before STREQUAL after)
  message(FATAL_ERROR "--out naming the scene changed the scene")
endif()
refused("--set spp: got \"abc\", expected not given with --spp" render ${scene} --method reference --spp 4 --set spp=abc)

# Resource limits: --timeout cancels at the next progress report (the DOM reports each sweep; the
# cloud takes about a second; under the sanitizers no report may come within the watchdog's grace,
# which then ends the work), --max-memory refuses a solution before it is allocated.
file(COPY ${SOURCE_DIR}/examples/cloud_lamps.json DESTINATION ${WORK_DIR})
set(cloud ${WORK_DIR}/cloud_lamps.json)
refused("--timeout: got 0.05 s, expected enough time for the" render ${cloud} --method dom --timeout 0.05 --out ${WORK_DIR}/t.exr)
refused("dom grid: got 271.3 MiB for 141696 cells x 128 directions, expected work that fits in the 100 MiB of the memory cap"
        render ${cloud} --method dom --max-memory 100 --out ${WORK_DIR}/m.exr)
refused("lights: got 1.6 MiB for 3 optical-depth volumes of 64 x 41 x 54 cells, expected work that fits in the 1 MiB"
        render ${cloud} --method propagation --max-memory 1 --out ${WORK_DIR}/m.exr)
