# haze demo's showcase on one row of two frames (paper 001's 512 particles): without a reference the
# table says so; --make-references makes one, after which the row has an error figure and its
# reference noise; a showcase changed since (3 frames) finds its reference stale; a row not in
# bench/seeds/rows.json is refused by name. The preview is a GIF. Arguments: -DHAZE -DWORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR}/examples/demo)
function(showcase frames row)
  file(WRITE ${WORK_DIR}/examples/demo/showcase.json
       "{\"made_by\": \"test\", \"frames\": ${frames}, \"error_width\": 8, \"target_noise\": 0.3, \"rows\": [{\"paper\": \"001\", \"row\": \"${row}\"}]}")
endfunction()
function(demo)
  execute_process(COMMAND ${HAZE} demo --examples ${WORK_DIR}/examples --out ${WORK_DIR}/out --threads 1 ${ARGN}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(rc ${rc} PARENT_SCOPE)
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()
set(row "figure 8: 512 particles, D 128")

showcase(2 "${row}")
demo()
if(NOT rc EQUAL 0 OR NOT out MATCHES "\\| 001 \\| ${row} \\|[^\n]*\\| no reference \\(test\\) \\|")
  message(FATAL_ERROR "without a reference (${rc}):\n${out}\n${err}")
endif()
file(READ ${WORK_DIR}/out/paper001.gif head LIMIT 6 HEX)
if(NOT head STREQUAL "474946383961")
  message(FATAL_ERROR "paper001.gif starts with ${head} (hex), not GIF89a")
endif()

demo(--make-references --reference-seconds 5)
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK_DIR}/examples/demo/paper001.exr)
  message(FATAL_ERROR "--make-references (${rc}):\n${out}\n${err}")
endif()
demo()
if(NOT rc EQUAL 0 OR NOT out MATCHES "\\| 001 \\| ${row} \\|[^\n]*\\| [0-9.]+% \\([0-9.]+%\\) \\|")
  message(FATAL_ERROR "with its reference (${rc}):\n${out}\n${err}")
endif()

showcase(3 "${row}")
demo()
if(NOT rc EQUAL 0 OR NOT out MATCHES "stale reference \\(test\\)")
  message(FATAL_ERROR "3 frames against the 2-frame reference (${rc}):\n${out}\n${err}")
endif()

showcase(2 "figure 9")
demo()
if(rc EQUAL 0 OR NOT err MATCHES "rows: got \\{\"paper\":\"001\",\"row\":\"figure 9\"\\}, expected a paper and row of bench/seeds/rows.json")
  message(FATAL_ERROR "an unknown row (${rc}):\n${out}\n${err}")
endif()
