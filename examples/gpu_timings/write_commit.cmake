# Writes OUT, a header defining BOUNCE_SOURCE_COMMIT: the short hash of SOURCE_DIR's HEAD,
# "+dirty" when tracked files differ from it, "unknown" without git. Rewritten only when the
# text changes, so an unchanged commit recompiles nothing.
execute_process(COMMAND git -C ${SOURCE_DIR} rev-parse --short HEAD
  OUTPUT_VARIABLE hash OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
if(failed OR hash STREQUAL "")
  set(hash "unknown")
else()
  execute_process(COMMAND git -C ${SOURCE_DIR} status --porcelain --untracked-files=no
    OUTPUT_VARIABLE dirty OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NOT dirty STREQUAL "")
    string(APPEND hash "+dirty")
  endif()
endif()
set(text "#pragma once\n#define BOUNCE_SOURCE_COMMIT \"${hash}\"\n")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
