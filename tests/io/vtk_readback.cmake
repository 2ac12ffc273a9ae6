# ctest vtk_readback: write the example series, then read them back with VTK's Python reader.
#   cmake -DWRITER=... -DPYTHON=/usr/bin/python3 -DSCRIPT=read_vtk_series.py -DWORK_DIR=... -P vtk_readback.cmake
if(NOT PYTHON OR NOT EXISTS "${PYTHON}")
  message(FATAL_ERROR "vtk_readback: /usr/bin/python3 not found; install python3 and python3-vtk9 "
                      "(scripts/install-deps.sh)")
endif()
execute_process(COMMAND ${PYTHON} -c "import vtk" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "vtk_readback: ${PYTHON} cannot import vtk (${err}); install python3-vtk9 "
                      "(scripts/install-deps.sh)")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${WRITER} ${WORK_DIR} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "vtk_readback: write_vtk_example failed (${rc})")
endif()
execute_process(COMMAND ${PYTHON} ${SCRIPT} ${WORK_DIR}/expected.json RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "vtk_readback: read_vtk_series.py failed (${rc})")
endif()
