# cmake -DPROGRAM=... -DARGS=a;b -DMATCH=regex -DSECONDS=s -DWORKDIR=dir -P run_refusal.cmake
# Passes when PROGRAM exits non-zero (not by a signal) within SECONDS and prints MATCH.
string(TIMESTAMP t0 "%s")
execute_process(COMMAND ${PROGRAM} ${ARGS} WORKING_DIRECTORY ${WORKDIR}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT ${SECONDS})
string(TIMESTAMP t1 "%s")
math(EXPR elapsed "${t1} - ${t0}")
set(all "${out}${err}")
if(rc STREQUAL "0")
  message(FATAL_ERROR "exited 0; expected a refusal matching '${MATCH}'. Output:\n${all}")
endif()
if(NOT rc MATCHES "^[0-9]+$" OR rc GREATER 125)
  message(FATAL_ERROR "did not exit with an error code (rc '${rc}': a crash, signal or time-out after ${elapsed} s). Output:\n${all}")
endif()
if(NOT all MATCHES "${MATCH}")
  message(FATAL_ERROR "exit ${rc}, but the message does not match '${MATCH}'. Output:\n${all}")
endif()
message(STATUS "refused in ${elapsed} s (exit ${rc}): ${all}")
