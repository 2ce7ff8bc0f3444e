# mpirun -np 2 haze render --method dom (issue 27): rank 0 alone prints one JSON summary, whose
# stats give the ranks, each rank's cells and its wait, and writes the image, which is the
# single process's (haze compare: relative RMSE under 1e-5); a --max-memory that one process
# refuses (16^3 cells: 2.8 MiB) is met by 4 ranks (0.7 MiB each); any other method is refused on
# every rank. Arguments: -DHAZE -DMPIEXEC -DSOURCE_DIR -DWORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(scene ${SOURCE_DIR}/examples/smoke_rbf.json)
set(settings --set resolution=16 --set directions=32 --set terms=9 --threads 1 --no-png)

execute_process(COMMAND ${MPIEXEC} -np 2 --oversubscribe ${HAZE} render ${scene} --method dom ${settings} --json --out ${WORK_DIR}/split.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mpirun haze render failed (${rc}):\n${out}\n${err}")
endif()
string(REGEX MATCHALL "\"method\": \"dom\"" summaries "${out}")
list(LENGTH summaries count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one summary (rank 0's), got ${count}:\n${out}")
endif()
string(JSON ranks GET "${out}" stats ranks)
string(JSON cells0 GET "${out}" stats rank_cells 0)
string(JSON cells1 GET "${out}" stats rank_cells 1)
string(JSON wait1 GET "${out}" stats rank_wait_seconds 1)
if(NOT ranks EQUAL 2 OR cells0 LESS 1 OR cells1 LESS 1 OR wait1 STREQUAL "")
  message(FATAL_ERROR "expected ranks 2 with each rank's cells and wait in the stats:\n${out}")
endif()

execute_process(COMMAND ${HAZE} render ${scene} --method dom ${settings} --out ${WORK_DIR}/single.exr RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "haze render failed: ${err}")
endif()
execute_process(COMMAND ${HAZE} compare ${WORK_DIR}/split.exr ${WORK_DIR}/single.exr --json OUTPUT_VARIABLE compared)
string(JSON relative GET "${compared}" relative_rmse)
if(NOT relative LESS 1e-5)
  message(FATAL_ERROR "the split render is ${relative} (relative RMSE) from the single process's")
endif()
message(STATUS "mpirun -np 2: relative RMSE ${relative} from the single process's image")

execute_process(COMMAND ${HAZE} render ${scene} --method dom ${settings} --max-memory 1.5 --out ${WORK_DIR}/capped.exr RESULT_VARIABLE rc ERROR_VARIABLE err)
string(FIND "${err}" "dom grid: got 2.8 MiB for 4096 cells x 32 directions, expected work that fits in the 1.5 MiB" at)
if(rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "haze render --max-memory 1.5: expected the memory error, got (${rc}):\n${err}")
endif()
execute_process(COMMAND ${MPIEXEC} -np 4 --oversubscribe ${HAZE} render ${scene} --method dom ${settings} --max-memory 1.5 --out ${WORK_DIR}/capped.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK_DIR}/capped.exr)
  message(FATAL_ERROR "mpirun -np 4 haze render --max-memory 1.5 failed (${rc}):\n${out}\n${err}")
endif()

execute_process(COMMAND ${MPIEXEC} -np 2 --oversubscribe ${HAZE} render ${scene} --method propagation --out ${WORK_DIR}/p.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(FIND "${err}" "error: method.name: got propagation, expected a method split over processes under 2 ranks (dom), or one process" at)
if(rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "mpirun haze render --method propagation: expected the method error, got (${rc}):\n${err}")
endif()
