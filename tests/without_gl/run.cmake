# HAZE_WITH_GL=OFF: configures the source tree without the GL module (and without benchmarks),
# builds it and runs its own test suite. Arguments: -DSOURCE_DIR -DWORK_DIR -DJOBS.
include(${CMAKE_CURRENT_LIST_DIR}/../run_step.cmake)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -DCMAKE_BUILD_TYPE=Release -DHAZE_WITH_GL=OFF
    -DHAZE_BUILD_BENCH=OFF -DHAZE_WERROR=ON)
run(${CMAKE_COMMAND} --build ${WORK_DIR} -j ${JOBS})
if(EXISTS ${WORK_DIR}/gl OR EXISTS ${WORK_DIR}/tests/gl_test)
  message(FATAL_ERROR "HAZE_WITH_GL=OFF still built the GL module or its tests")
endif()
# The GL-less suite, less this test itself (it is not registered there) and the install consumer,
# which the main suite runs.
run(${CMAKE_CTEST_COMMAND} --test-dir ${WORK_DIR} -j ${JOBS} -E install_consumer --output-on-failure)
message("${last_output}")
