# cmake -DPROGRAM=exe -DARGS="arg1|arg2|..." -DEXIT=<code>|nonzero
#       [-DSTDOUT_MATCH=regex] [-DSTDERR_MATCH=regex] [-DSTDERR_NO_MATCH=regex]
#       [-DOUTPUT_FILE=path] [-DNO_OUTPUT_FILE=path|path...] [-DUNCHANGED_FILE=path|path...]
#       -P check_command.cmake
# Runs PROGRAM with ARGS ('|' separates them: arguments may hold commas and
# semicolons would split them in add_test) and passes when the exit status is
# EXIT (a number, or "nonzero": any exit status > 0, not a crash), stdout and
# stderr match their regexes (separately, so that a message is known to be on
# the right stream), stderr does not match STDERR_NO_MATCH, OUTPUT_FILE
# (removed before the run) exists after it and none of NO_OUTPUT_FILE (removed
# before the run too: a refused command must not write its output) does, and
# every UNCHANGED_FILE still exists with the bytes it had before the run.
# CMake regexes have no multi-line mode: ^ and $ are the ends of the whole
# stream, so a line is anchored with (^|\n) ... (\n|$).
if(NOT DEFINED PROGRAM OR NOT DEFINED EXIT)
  message(FATAL_ERROR "check_command.cmake: give -DPROGRAM=... and -DEXIT=...")
endif()
string(REPLACE "|" ";" args "${ARGS}")
if(DEFINED OUTPUT_FILE)
  file(REMOVE "${OUTPUT_FILE}")
endif()
string(REPLACE "|" ";" no_output_files "${NO_OUTPUT_FILE}")
foreach(f IN LISTS no_output_files)
  file(REMOVE "${f}")
endforeach()
string(REPLACE "|" ";" unchanged_files "${UNCHANGED_FILE}")
set(hashes_before "")
foreach(f IN LISTS unchanged_files)
  file(SHA256 "${f}" hash)
  list(APPEND hashes_before "${hash}")
endforeach()
execute_process(COMMAND "${PROGRAM}" ${args} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "exit status: ${code}\n--- stdout:\n${out}--- stderr:\n${err}---")
set(failures "")
if(EXIT STREQUAL "nonzero")
  if(NOT code MATCHES "^[1-9][0-9]*$")
    string(APPEND failures "exit status '${code}', expected a non-zero exit status\n")
  endif()
elseif(NOT code STREQUAL EXIT)
  string(APPEND failures "exit status '${code}', expected ${EXIT}\n")
endif()
if(DEFINED STDOUT_MATCH AND NOT out MATCHES "${STDOUT_MATCH}")
  string(APPEND failures "stdout does not match '${STDOUT_MATCH}'\n")
endif()
if(DEFINED STDERR_MATCH AND NOT err MATCHES "${STDERR_MATCH}")
  string(APPEND failures "stderr does not match '${STDERR_MATCH}'\n")
endif()
if(DEFINED STDERR_NO_MATCH AND err MATCHES "${STDERR_NO_MATCH}")
  string(APPEND failures "stderr matches '${STDERR_NO_MATCH}', which it must not\n")
endif()
if(DEFINED OUTPUT_FILE AND NOT EXISTS "${OUTPUT_FILE}")
  string(APPEND failures "${OUTPUT_FILE} was not written\n")
endif()
foreach(f IN LISTS no_output_files)
  if(EXISTS "${f}")
    string(APPEND failures "${f} was written, which it must not be\n")
  endif()
endforeach()
foreach(f hash_before IN ZIP_LISTS unchanged_files hashes_before)
  if(NOT EXISTS "${f}")
    string(APPEND failures "${f} is gone, which it must not be\n")
  else()
    file(SHA256 "${f}" hash)
    if(NOT hash STREQUAL hash_before)
      string(APPEND failures "${f} was changed, which it must not be\n")
    endif()
  endif()
endforeach()
if(failures)
  message(FATAL_ERROR "${failures}")
endif()
