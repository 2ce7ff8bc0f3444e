# Installs the build tree into a scratch prefix, then configures, builds and runs, against it with
# find_package(haze), the consumer project and the API examples (examples/api). Arguments:
# -DBUILD_DIR -DSOURCE_DIR -DWORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
include(${CMAKE_CURRENT_LIST_DIR}/../run_step.cmake)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(project consumer api)
  if(project STREQUAL "consumer")
    set(source ${SOURCE_DIR}/tests/install/consumer)
  else()
    set(source ${SOURCE_DIR}/examples/api)
  endif()
  # Components core and grids need neither FLANN nor GL: finding them is made to fail.
  run(${CMAKE_COMMAND} -S ${source} -B ${WORK_DIR}/${project} -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_DISABLE_FIND_PACKAGE_flann=ON -DCMAKE_DISABLE_FIND_PACKAGE_OpenGL=ON)
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/${project})
endforeach()

# The whole package, and a component it does not have.
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/components -B ${WORK_DIR}/components -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)

execute_process(COMMAND ${WORK_DIR}/consumer/consumer WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message("${out}")
if(NOT rc EQUAL 0 OR NOT out MATCHES "relative error 0\\.0[6-9]" OR NOT out MATCHES "error: method.name")
  message(FATAL_ERROR "consumer failed or printed the unexpected (${rc})")
endif()

# The simulation: 10 frames written, and the DOM's fluence at the puff's centre follows the puff
# (its first and last frames differ).
execute_process(COMMAND ${WORK_DIR}/api/simulation ${WORK_DIR}/frames RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message("${out}")
string(REGEX MATCHALL "\n +[0-9] +[0-9.]+ +[0-9.]+ +[0-9.]+ +([0-9.]+)" rows "${out}")
list(LENGTH rows frames)
list(GET rows 0 first)
list(GET rows -1 last)
string(REGEX REPLACE ".* " "" first "${first}")
string(REGEX REPLACE ".* " "" last "${last}")
if(NOT rc EQUAL 0 OR NOT frames EQUAL 10 OR first STREQUAL last OR NOT EXISTS ${WORK_DIR}/frames/frame_09.exr)
  message(FATAL_ERROR "simulation failed (${rc}), printed ${frames} frames, or its fluence did not change (${first} -> ${last})")
endif()

# One solution, two cameras: both views rendered and written, and they differ.
execute_process(COMMAND ${WORK_DIR}/api/two_cameras ${WORK_DIR}/views RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message("${out}")
string(REGEX MATCH "front: [0-9.]+ s, mean radiance ([0-9.]+)" front "${out}")
set(front ${CMAKE_MATCH_1})
string(REGEX MATCH "side: [0-9.]+ s, mean radiance ([0-9.]+)" side "${out}")
set(side ${CMAKE_MATCH_1})
if(NOT rc EQUAL 0 OR NOT front OR NOT side OR front STREQUAL side OR NOT EXISTS ${WORK_DIR}/views/side.exr)
  message(FATAL_ERROR "two_cameras failed (${rc}) or its views are missing or alike (${front}, ${side})")
endif()
