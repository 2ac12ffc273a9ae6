# ctest brownian_rods_continued: a melt of 20 steps written by --save-state, against 10 steps
# saved, read back by --load-state and continued for 10 more. The two checkpoints must hold
# the same poses and Brownian stream to the last digit (io/checkpoint.hpp); the time lines
# may differ in the last bit (t0 + 20 dt against (t0 + 10 dt) + 10 dt) and are not compared.
# Then the checkpoint loaded with another --n must be refused, and loaded at another packing
# it must be expanded or compressed to it. Last, a run stopped by a timeout must keep its lines.
# Usage: cmake -DDRIVER=<brownian_rods> -DWORK_DIR=<dir> -P check_continued_run.cmake
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(common --n 300 --eta 0.3 --u0 0 --dt 5e-4 --melt-dt 5e-4 --equilibrate 0 --average 0.002
           --directions overlap-ends --overlap-ends-angle 0.3)
foreach(run IN ITEMS "whole;--start;aligned;--melt;0.01" "half;--start;aligned;--melt;0.005;--save-every;3"
                     "continued;--load-state;${WORK_DIR}/half.checkpoint;--melt;0.005")
  list(POP_FRONT run name)
  execute_process(COMMAND ${DRIVER} ${common} ${run} --save-state ${WORK_DIR}/${name}.checkpoint
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ERROR: brownian_rods (${name}) failed with ${rc}:\n${out}\n${err}")
  endif()
endforeach()
file(STRINGS ${WORK_DIR}/whole.checkpoint whole)
file(STRINGS ${WORK_DIR}/continued.checkpoint continued)
list(FILTER whole EXCLUDE REGEX "^time ")
list(FILTER continued EXCLUDE REGEX "^time ")
list(LENGTH whole lines)
if(NOT lines EQUAL 305)  # header, box, bodies, 300 poses, noise, end
  message(FATAL_ERROR "ERROR: the checkpoint has ${lines} lines besides the time, expected 305")
endif()
if(NOT whole STREQUAL continued)
  message(FATAL_ERROR "ERROR: the continued run's checkpoint differs from the uninterrupted run's")
endif()
# A checkpoint of another system is refused, naming what differs.
list(TRANSFORM common REPLACE "^300$" "200")
execute_process(COMMAND ${DRIVER} ${common} --load-state ${WORK_DIR}/half.checkpoint --melt 0.001
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT "${out}${err}" MATCHES "holds 300 rods, --n is 200")
  message(FATAL_ERROR "ERROR: a checkpoint of 300 rods loaded with --n 200 gave ${rc}:\n${out}\n${err}")
endif()
# A checkpoint at another packing is brought to --eta: expanded at once (0.3 -> 0.28), or
# compressed in rescalings with Brownian steps between them (0.3 -> 0.305); both then melt.
list(TRANSFORM common REPLACE "^200$" "300")
foreach(case IN ITEMS "0.28;expansion: side [0-9.]+ -> [0-9.]+ \\(eta 0.3000 -> 0.2800\\)"
                      "0.305;compression from eta 0.3000:.*compression: [1-9][0-9]* rescalings")
  list(POP_FRONT case eta)
  set(args ${common})
  list(FIND args --eta at)
  math(EXPR at "${at} + 1")
  list(REMOVE_AT args ${at})
  list(INSERT args ${at} ${eta})
  execute_process(COMMAND ${DRIVER} ${args} --load-state ${WORK_DIR}/half.checkpoint --melt 0.001
                          --compress-rate 2e-3 --compress-steps 1 --save-state ${WORK_DIR}/at_${eta}.checkpoint
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT "${out}" MATCHES "${case}")
    message(FATAL_ERROR "ERROR: the checkpoint at eta 0.3 loaded at --eta ${eta} gave ${rc}:\n${out}\n${err}")
  endif()
  # The file it saves is at the new packing: loaded again at --eta it is taken as it is.
  execute_process(COMMAND ${DRIVER} ${args} --load-state ${WORK_DIR}/at_${eta}.checkpoint --melt 0.001
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR "${out}" MATCHES "expansion|compression")
    message(FATAL_ERROR "ERROR: the checkpoint saved at --eta ${eta} was not taken as it is:\n${out}\n${err}")
  endif()
endforeach()
# A long run stopped from outside (here by execute_process's timeout) keeps the lines it
# printed: the driver's stdout is line-buffered even into a pipe or a file (cli.hpp).
execute_process(COMMAND ${DRIVER} ${common} --load-state ${WORK_DIR}/half.checkpoint --melt 100 TIMEOUT 5
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT "${out}" MATCHES "Brownian rods: N = 300 spherocylinders")
  message(FATAL_ERROR "ERROR: a run stopped after 5 s gave ${rc} and lost its first lines:\n${out}\n${err}")
endif()
message(STATUS "continued run: the same 300 poses and Brownian stream as the uninterrupted run; "
               "a checkpoint expanded and compressed to another packing; a stopped run keeps its lines")
