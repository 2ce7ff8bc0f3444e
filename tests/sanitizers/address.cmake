# HAZE_WITH_GL=OFF: configures the source tree without the GL module (and without benchmarks),
# as shared libraries with hidden symbols (BUILD_SHARED_LIBS: the tests and apps link through the
# public headers' exports alone), builds it and runs its own test suite.
# Arguments: -DSOURCE_DIR -DWORK_DIR -DJOBS.
include(${CMAKE_CURRENT_LIST_DIR}/../run_step.cmake)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -DCMAKE_BUILD_TYPE=Release -DHAZE_WITH_GL=OFF
    -DHAZE_BUILD_BENCH=OFF -DHAZE_WERROR=ON -DBUILD_SHARED_LIBS=ON)
run(${CMAKE_COMMAND} --build ${WORK_DIR} -j ${JOBS})
if(EXISTS ${WORK_DIR}/gl OR EXISTS ${WORK_DIR}/tests/gl_test)
  message(FATAL_ERROR "HAZE_WITH_GL=OFF still built the GL module or its tests")
endif()
# Shared, and hiding what no public header declares: the scene parser's helpers stay internal.
if(NOT EXISTS ${WORK_DIR}/core/libhaze_core.so)
  message(FATAL_ERROR "BUILD_SHARED_LIBS=ON built no libhaze_core.so")
endif()
execute_process(COMMAND nm -D --defined-only -C ${WORK_DIR}/core/libhaze_core.so OUTPUT_VARIABLE exported)
if(NOT exported MATCHES "haze::Scene::from_json" OR exported MATCHES "haze::\(anonymous namespace\)")
  message(FATAL_ERROR "libhaze_core.so does not export haze::Scene::from_json, or exports internal symbols")
endif()
# The GL-less suite, less this test itself (it is not registered there) and the install consumer,
# which the main suite runs.
run(${CMAKE_CTEST_COMMAND} --test-dir ${WORK_DIR} -j ${JOBS} -E install_consumer --output-on-failure)
message("${last_output}")
