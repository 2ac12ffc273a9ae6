# Installs StokesContact into a scratch prefix and builds, then runs, a separate project that
# finds it with find_package(stokescontact REQUIRED).
#   NLOPT=ON:  installs BUILD_DIR (the project's own build, with NLopt);
#   NLOPT=OFF: configures the library alone from SOURCE_DIR with STOKESCONTACT_USE_NLOPT=OFF
#              and installs that: the consumer must build and run without NLopt's target.
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

function(run_step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "step failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

if(NLOPT)
  set(install_from ${BUILD_DIR})
  set(expect 1)
else()
  set(install_from ${WORK_DIR}/library)
  run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${install_from} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
           -DSTOKESCONTACT_USE_NLOPT=OFF -DSTOKESCONTACT_BUILD_TESTS=OFF
           -DSTOKESCONTACT_BUILD_BENCHMARKS=OFF -DSTOKESCONTACT_BUILD_EXAMPLES=OFF
           -DSTOKESCONTACT_BUILD_RUNNER=OFF)
  set(expect 0)
endif()
run_step(${CMAKE_COMMAND} --install ${install_from} --prefix ${prefix})
file(READ ${prefix}/share/stokescontact/cmake/stokescontactTargets.cmake targets)
if(NOT NLOPT AND targets MATCHES "nlopt")
  message(FATAL_ERROR "the package configured without NLopt still names it:\n${targets}")
endif()
# No build type (no optimisation): the test is about the package, and the consumer's one
# translation unit (the umbrella header and a contact step) compiles in 69 s against 94 s
# at -O3 (GCC 12).
run_step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/package/consumer -B ${WORK_DIR}/build
         -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
         -DCMAKE_BUILD_TYPE= -DEXPECT_NLOPT=${expect})
run_step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run_step(${WORK_DIR}/build/consumer)
# The runner is installed with the package (built with NLopt, as the project's own build is):
# it runs an example scene from the prefix for two steps.
if(NLOPT)
  run_step(${prefix}/bin/stokescontact-run ${SOURCE_DIR}/examples/scenes/biaxial_rods.json
           --output ${WORK_DIR}/run --max-steps 2 --quiet)
endif()
