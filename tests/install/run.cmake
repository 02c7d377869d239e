# ctest script: installs the build into a fresh prefix, configures and builds tests/install
# against it, and runs the consumer on a fixture. Variables: BUILD_DIR, SOURCE_DIR, WORK_DIR,
# FIXTURE, EXPECTED (the consumer's expected output line), GEN (meshstream-gen, which makes a
# mesh large enough to be cut into two ranges) and LARGE_EXPECTED (README's program's line for
# it, on two threads),
# CXX_FLAGS and LINKER_FLAGS (the build's own, e.g. sanitizers, which the installed static
# libraries need at link time).
file(REMOVE_RECURSE "${WORK_DIR}")
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()
step(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
step(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix"
     -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}")
step(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
step("${WORK_DIR}/build/consumer" "${FIXTURE}")
string(STRIP "${step_output}" got)
if(NOT got STREQUAL "${EXPECTED}")
  message(FATAL_ERROR "consumer printed '${got}', expected '${EXPECTED}'")
endif()
# README's program: the file decimated on two threads, written, and read back.
step("${GEN}" --quiet --triangles 900000 "${WORK_DIR}/large.stl")
step("${WORK_DIR}/build/decimate_file" "${WORK_DIR}/large.stl" "${WORK_DIR}/large_10.ply" 2)
string(STRIP "${step_output}" got)
if(NOT got STREQUAL "${LARGE_EXPECTED}")
  message(FATAL_ERROR "decimate_file printed '${got}', expected '${LARGE_EXPECTED}'")
endif()
step("${WORK_DIR}/build/consumer" "${WORK_DIR}/large_10.ply")
string(REGEX MATCH "^[0-9]+" read_back "${step_output}")
string(REPLACE " " ";" expected_fields "${LARGE_EXPECTED}")
list(GET expected_fields 1 written)
if(NOT read_back STREQUAL written)
  message(FATAL_ERROR "decimate_file's output holds ${read_back} triangles, it said ${written}")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
