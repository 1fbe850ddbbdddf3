# Extracts the C and C++ snippets of a markdown page (README.md, docs/*.md).
#
#   ldc_docs_extract(<page.md> <prefix>)
#
# Every fenced block opened by ```cpp or ```c (indented or not) is a snippet.
# An HTML comment on the line right before the fence says what to do with it:
#
#   (none)                              compiled (-Werror), not run
#   <!-- snippet: run -->               compiled, linked and run; defines main()
#   <!-- snippet: run EXPR -->          compiled, linked and run: a main() is
#                                       appended that evaluates EXPR (an
#                                       ldc::Status or ldc::Result, e.g. a call
#                                       of the snippet's function) and exits 0
#                                       when it is ok
#   <!-- snippet: no-compile (reason) --> skipped (pseudo-code, an error shown
#                                       on purpose); counted
#
# Sets in the caller's scope: <prefix>_COUNT and, for i in 1 .. COUNT,
#   <prefix>_<i>_LANG   cpp or c
#   <prefix>_<i>_FENCE  line number of the opening fence (1-based)
#   <prefix>_<i>_MODE   compile, run or no-compile
#   <prefix>_<i>_ARG    the run expression, or the no-compile reason
#   <prefix>_<i>_TU     TRUE when the snippet defines a function at file scope
#                       (a complete translation unit: compiled as it is),
#                       FALSE for a fragment (statements: wrapped in a function)
#   <prefix>_<i>_MAIN   TRUE when it defines main()
#   <prefix>_<i>_CODE   the code, indentation of the fence removed
# Other fence languages (cmake, sh, json, none) are left alone. An unknown
# `snippet:` mark or one not followed by a C/C++ fence is a fatal error.

# A line that opens a function definition at file scope: a return type, a
# name, a parameter list closed on the same line and the opening brace.
set(LDC_DOCS_FUNCTION_REGEX
    "^[A-Za-z_][A-Za-z0-9_:<>,*& \t]*[ \t*&]~?[A-Za-z_][A-Za-z0-9_:]*[ \t]*\\(.*\\)[ \t]*(const[ \t]*)?(noexcept[ \t]*)?{[ \t]*(//.*|/\\*.*)?$")
set(LDC_DOCS_CONTROL_REGEX "^(if|for|while|switch|else|do|return|case)[ \t(]")

function(ldc_docs_extract page prefix)
  file(READ "${page}" text)
  # One list element per line: protect the characters CMake lists treat specially.
  string(REPLACE "\\" "<ldc-bs>" text "${text}")
  string(REPLACE ";" "<ldc-semi>" text "${text}")
  string(REPLACE "[" "<ldc-lb>" text "${text}")
  string(REPLACE "]" "<ldc-rb>" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")

  set(count 0)
  set(line_no 0)
  set(in_block FALSE)       # inside a snippet
  set(in_other FALSE)       # inside another fenced block
  set(pending_mode "")      # a mark seen on the previous line
  set(pending_arg "")
  set(pending_line 0)
  foreach(line IN LISTS lines)
    math(EXPR line_no "${line_no} + 1")
    if(in_block)
      if(line MATCHES "^[ \t]*```[ \t]*$")
        set(in_block FALSE)
        string(REPLACE "<ldc-bs>" "\\" code "${code}")
        string(REPLACE "<ldc-semi>" ";" code "${code}")
        string(REPLACE "<ldc-lb>" "[" code "${code}")
        string(REPLACE "<ldc-rb>" "]" code "${code}")
        set(${prefix}_${count}_CODE "${code}" PARENT_SCOPE)
        set(${prefix}_${count}_TU ${tu} PARENT_SCOPE)
        set(${prefix}_${count}_MAIN ${has_main} PARENT_SCOPE)
        continue()
      endif()
      # Remove the fence's indentation (a block inside a list item).
      if(indent GREATER 0)
        string(LENGTH "${line}" len)
        if(len GREATER_EQUAL indent)
          string(SUBSTRING "${line}" 0 ${indent} lead)
          if(lead MATCHES "^[ ]+$")
            string(SUBSTRING "${line}" ${indent} -1 line)
          endif()
        endif()
      endif()
      string(APPEND code "${line}\n")
      string(REPLACE "<ldc-lb>" "[" plain "${line}")
      string(REPLACE "<ldc-rb>" "]" plain "${plain}")
      if(plain MATCHES "${LDC_DOCS_FUNCTION_REGEX}" AND NOT plain MATCHES "${LDC_DOCS_CONTROL_REGEX}")
        set(tu TRUE)
      endif()
      if(plain MATCHES "^int[ \t]+main[ \t]*\\(")
        set(has_main TRUE)
      endif()
      continue()
    endif()
    if(in_other)
      if(line MATCHES "^[ \t]*```[ \t]*$")
        set(in_other FALSE)
      endif()
      continue()
    endif()
    if(line MATCHES "^([ ]*)```[ \t]*(cpp|c)[ \t]*$")
      string(LENGTH "${CMAKE_MATCH_1}" indent)
      set(lang ${CMAKE_MATCH_2})
      math(EXPR count "${count} + 1")
      math(EXPR prev "${line_no} - 1")
      if(pending_mode STREQUAL "" OR NOT pending_line EQUAL prev)
        set(mode compile)
        set(arg "")
      else()
        set(mode ${pending_mode})
        set(arg "${pending_arg}")
      endif()
      set(pending_mode "")
      set(${prefix}_${count}_LANG ${lang} PARENT_SCOPE)
      set(${prefix}_${count}_FENCE ${line_no} PARENT_SCOPE)
      set(fence_line ${line_no})
      set(${prefix}_${count}_MODE ${mode} PARENT_SCOPE)
      set(${prefix}_${count}_ARG "${arg}" PARENT_SCOPE)
      set(in_block TRUE)
      set(code "")
      set(tu FALSE)
      set(has_main FALSE)
      continue()
    endif()
    if(line MATCHES "^[ \t]*```[^`]*$")  # a fence's info string holds no backtick
      if(NOT pending_mode STREQUAL "")
        message(FATAL_ERROR "${page}:${pending_line}: a snippet mark before a block that is not ```cpp or ```c")
      endif()
      set(in_other TRUE)
      continue()
    endif()
    if(NOT pending_mode STREQUAL "")
      message(FATAL_ERROR "${page}:${pending_line}: a snippet mark must be on the line right before a ```cpp or ```c fence")
    endif()
    if(line MATCHES "^[ \t]*<!--[ \t]*snippet:")
      string(REPLACE "<ldc-lb>" "[" plain "${line}")
      string(REPLACE "<ldc-rb>" "]" plain "${plain}")
      string(REPLACE "<ldc-semi>" ";" plain "${plain}")
      string(REPLACE "<ldc-bs>" "\\" plain "${plain}")
      if(plain MATCHES "^[ \t]*<!--[ \t]*snippet:[ \t]*run([ \t].*)?-->[ \t]*$")
        set(pending_mode run)
        string(STRIP "${CMAKE_MATCH_1}" pending_arg)
      elseif(plain MATCHES "^[ \t]*<!--[ \t]*snippet:[ \t]*no-compile[ \t]+(\\(.+\\))[ \t]*-->[ \t]*$")
        set(pending_mode no-compile)
        set(pending_arg "${CMAKE_MATCH_1}")
      else()
        message(FATAL_ERROR "${page}:${line_no}: unknown snippet mark '${plain}': use "
                            "<!-- snippet: run -->, <!-- snippet: run EXPR --> or <!-- snippet: no-compile (reason) -->")
      endif()
      set(pending_line ${line_no})
    endif()
  endforeach()
  if(in_block)
    message(FATAL_ERROR "${page}: a ```${lang} block opened at line ${fence_line} is not closed")
  endif()
  if(NOT pending_mode STREQUAL "")
    message(FATAL_ERROR "${page}:${pending_line}: a snippet mark at the end of the page")
  endif()
  set(${prefix}_COUNT ${count} PARENT_SCOPE)
endfunction()

# Writes `content` to `path` only when it differs, so that an unchanged
# snippet is not rebuilt at every configure.
function(ldc_docs_write_if_changed path content)
  if(EXISTS "${path}")
    file(READ "${path}" old)
    if(old STREQUAL content)
      return()
    endif()
  endif()
  file(WRITE "${path}" "${content}")
endfunction()
