# Drives the independent Python tile-set reader against the C++ decoder (cmake -P; see CMakeLists.txt).
#   MODE=compare: `tileset_reader.py TILESET --summary` must equal `tileset_summary TILESET` byte for byte,
#                 and `--points 0` must print the first tile as "x y key level" lines.
#   MODE=damaged: one byte of a copy of TILESET flipped (WHERE=payload: mid-payload; WHERE=header: in the
#                 recipe text); both readers must exit non-zero naming the checksum that caught it.
# Variables: PYTHON, READER, SUMMARY, TILESET, WORK_DIR.
foreach(var PYTHON READER SUMMARY TILESET WORK_DIR MODE)
  if(NOT DEFINED ${var} OR "${${var}}" MATCHES "NOTFOUND$")
    message(FATAL_ERROR "python_reader.cmake: ${var} is unset (${${var}}); python3 missing? (scripts/deps)")
  endif()
endforeach()
file(MAKE_DIRECTORY ${WORK_DIR})

if(MODE STREQUAL "compare")
  execute_process(COMMAND ${PYTHON} ${READER} ${TILESET} --summary
                  RESULT_VARIABLE py_rc OUTPUT_VARIABLE py_out ERROR_VARIABLE py_err)
  execute_process(COMMAND ${SUMMARY} ${TILESET} RESULT_VARIABLE cpp_rc OUTPUT_VARIABLE cpp_out
                  ERROR_VARIABLE cpp_err)
  file(WRITE ${WORK_DIR}/python.summary "${py_out}")
  file(WRITE ${WORK_DIR}/cpp.summary "${cpp_out}")
  if(NOT py_rc EQUAL 0)
    message(FATAL_ERROR "the Python reader failed (${py_rc}): ${py_err}")
  endif()
  if(NOT cpp_rc EQUAL 0)
    message(FATAL_ERROR "tileset_summary failed (${cpp_rc}): ${cpp_err}")
  endif()
  if(NOT py_out STREQUAL cpp_out)
    execute_process(COMMAND diff -u ${WORK_DIR}/cpp.summary ${WORK_DIR}/python.summary OUTPUT_VARIABLE diff)
    message(FATAL_ERROR "the summaries differ (cpp.summary vs python.summary in ${WORK_DIR}):\n${diff}")
  endif()
  string(REGEX MATCH "\ntile 0 points ([0-9]+) " _ "${cpp_out}")
  set(tile0_points ${CMAKE_MATCH_1})
  execute_process(COMMAND ${PYTHON} ${READER} ${TILESET} --points 0 RESULT_VARIABLE rc OUTPUT_VARIABLE points
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--points 0 failed (${rc}): ${err}")
  endif()
  string(REGEX REPLACE "[^\n]" "" newlines "${points}")
  string(LENGTH "${newlines}" count)
  string(FIND "${points}" "\n" end)
  math(EXPR end "${end} + 1")
  string(SUBSTRING "${points}" 0 ${end} first)
  # Tile 0's first point is a level-0 point; x and y are unit-square doubles, (x + 0.5) / 65536.
  if(NOT count EQUAL tile0_points OR NOT first MATCHES "^0\\.[0-9]+ 0\\.[0-9]+ [0-9]+ 0\n$")
    message(FATAL_ERROR "--points 0 printed ${count} lines for ${tile0_points} points, first: ${first}")
  endif()
  string(LENGTH "${cpp_out}" size)
  message(STATUS "summaries agree (${size} bytes); --points 0 printed ${count} points")
elseif(MODE STREQUAL "damaged")
  if(WHERE STREQUAL "payload")
    set(py_expect "payload CRC-32 mismatch")
    set(cpp_expect "payload checksum mismatch")
  elseif(WHERE STREQUAL "header")
    set(py_expect "header CRC-32 mismatch")
    set(cpp_expect "header checksum mismatch")
  else()
    message(FATAL_ERROR "WHERE must be payload or header, not '${WHERE}'")
  endif()
  set(damaged ${WORK_DIR}/damaged_${WHERE}.kdmt)
  # No semicolons in the script: CMake would split it into list elements.
  set(flip "import sys
src, dst, where = sys.argv[1:4]
data = bytearray(open(src, 'rb').read())
header_size = int.from_bytes(data[12:16], 'little')
i = header_size + (len(data) - header_size) // 2 if where == 'payload' else 64
data[i] ^= 0x10
open(dst, 'wb').write(data)
")
  execute_process(COMMAND ${PYTHON} -c "${flip}" ${TILESET} ${damaged} ${WHERE}
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "could not write ${damaged}: ${err}")
  endif()
  execute_process(COMMAND ${PYTHON} ${READER} ${damaged} --summary
                  RESULT_VARIABLE py_rc OUTPUT_VARIABLE py_out ERROR_VARIABLE py_err)
  execute_process(COMMAND ${SUMMARY} ${damaged} RESULT_VARIABLE cpp_rc OUTPUT_VARIABLE cpp_out
                  ERROR_VARIABLE cpp_err)
  if(py_rc EQUAL 0 OR NOT py_err MATCHES "${py_expect}")
    message(FATAL_ERROR "the Python reader should refuse ${damaged} with '${py_expect}'; "
                        "exit ${py_rc}: ${py_err}")
  endif()
  if(cpp_rc EQUAL 0 OR NOT cpp_err MATCHES "${cpp_expect}")
    message(FATAL_ERROR "tileset_summary should refuse ${damaged} with '${cpp_expect}'; "
                        "exit ${cpp_rc}: ${cpp_err}")
  endif()
  message(STATUS "both readers refuse the damaged ${WHERE}:\n  ${py_err}  ${cpp_err}")
else()
  message(FATAL_ERROR "MODE must be compare or damaged, not '${MODE}'")
endif()
