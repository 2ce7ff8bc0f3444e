# ThreadSanitizer (GCC) over tests that run Haze's threaded code paths: the thread-count checks
# (quadrature, reference, airlight, RBF injection, propagation, the DOM's sweeps), solutions and
# their updates, the particle networks, neighbour search and cancellation.
# haze::parallel_for runs on std::threads in this build (TSan does not see the synchronisation in
# Debian's uninstrumented TBB). GL, Python, VDB and the apps are left out; -O1, one Highway
# target (simd_flags.cmake). Arguments: -DSOURCE_DIR -DWORK_DIR -DJOBS.
include(${CMAKE_CURRENT_LIST_DIR}/../run_step.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/simd_flags.cmake)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -DCMAKE_BUILD_TYPE=RelWithDebInfo
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" "-DCMAKE_CXX_FLAGS=${simd_flags}"
    -DHAZE_SANITIZE=thread -DHAZE_WITH_GL=OFF -DHAZE_WITH_PYTHON=OFF -DHAZE_WITH_MPI=OFF -DHAZE_BUILD_BENCH=OFF ${unity})
run(${CMAKE_COMMAND} --build ${WORK_DIR} -j ${JOBS} --target core_test grids_test particles_test)
# (Each runs 10 to 200 times slower under TSan: the DOM's other tests took 15 to 180 s each.)
set(threaded "ThreadCount|ThreadIndependent|Cancellation|^Solution.(Update|Renders|CallerGrids)|PropagationSolution"
             "GridSolution|NetworkUpdate.MatchesAFullBuild|NetworkSolution|NetworkDegenerate|VisibilityNetwork|Neighbours"
             "ParticleDensity")
string(JOIN "|" threaded ${threaded})
set(ENV{TSAN_OPTIONS} "halt_on_error=1:second_deadlock_stack=1")
run(${CMAKE_CTEST_COMMAND} --test-dir ${WORK_DIR} -j ${JOBS} -R "${threaded}" --output-on-failure)
message("${last_output}")
