# haze bench seeds --json on paper 001's rows (issue 52's measure), few frames and a small noisy
# reference: one row per row of bench/seeds/rows.json for that paper, each with its paper's frame
# rate (or null where the paper states none), Haze's above 0 and an error; an unknown paper is
# refused. The figures themselves are benchmarks, not asserted. Arguments: -DHAZE.
execute_process(COMMAND ${HAZE} bench seeds --json --paper 001 --frames 2 --spp 4 --error-width 8 --threads 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "haze bench seeds failed (${rc}):\n${out}\n${err}")
endif()
string(JSON rows LENGTH "${out}")
if(NOT rows EQUAL 4)
  message(FATAL_ERROR "expected paper 001's 4 rows, got ${rows}:\n${out}")
endif()
math(EXPR last "${rows} - 1")
foreach(i RANGE ${last})
  string(JSON paper GET "${out}" ${i} paper)
  string(JSON fps GET "${out}" ${i} fps)
  string(JSON paper_fps_type TYPE "${out}" ${i} paper_fps)
  string(JSON error_type TYPE "${out}" ${i} error)
  if(NOT paper STREQUAL "001" OR NOT fps GREATER 0 OR NOT paper_fps_type MATCHES "^(NUMBER|NULL)$" OR NOT error_type STREQUAL "NUMBER")
    message(FATAL_ERROR "row ${i}: paper ${paper}, fps ${fps}, paper_fps ${paper_fps_type}, error ${error_type}:\n${out}")
  endif()
endforeach()
execute_process(COMMAND ${HAZE} bench seeds --paper 009 RESULT_VARIABLE rc ERROR_VARIABLE err)
string(FIND "${err}" "--paper: got 009, expected one of 000, 001, 002, 003" at)
if(rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "haze bench seeds --paper 009: expected the --paper error, got (${rc}):\n${err}")
endif()
