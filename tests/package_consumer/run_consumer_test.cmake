# Install ULC into a temporary prefix, configure and build the consumer against it, run it.
file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} -S ${ULC_SOURCE_DIR} -B ${WORK_DIR}/ulc-build -G ${GENERATOR}
    -DULC_BUILD_TESTS=OFF -DULC_BUILD_EXAMPLES=OFF -DULC_BUILD_BENCH=OFF -DULC_BUILD_APPS=OFF
    -DCMAKE_INSTALL_PREFIX=${prefix})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/ulc-build)  # ulc::calibrate, the compiled pipeline
run(${CMAKE_COMMAND} --install ${WORK_DIR}/ulc-build)
run(${CMAKE_COMMAND} -S ${ULC_SOURCE_DIR}/tests/package_consumer -B ${WORK_DIR}/consumer-build
    -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/consumer-build)
run(${WORK_DIR}/consumer-build/consumer)
run(${WORK_DIR}/consumer-build/consumer_bags)
run(${WORK_DIR}/consumer-build/consumer_results)
run(${WORK_DIR}/consumer-build/consumer_calibrate)
