# kdm_bake_tileset's last step: runs `kdm verify` on the freshly baked scratch file (VERIFY), puts it in
# place of the tile set unless the set holds its bytes already, and marks the bake done (the stamp). A
# failed check removes the scratch file and leaves the set and the stamp as they were, so that the next
# build tries again. An unchanged set keeps its time, so that nothing built from it is built again.
#   cmake -DKDM_BAKE_SCRATCH=<scratch> -DKDM_BAKE_OUTPUT=<set> -DKDM_BAKE_STAMP=<stamp>
#         [-DKDM_VERIFY_KDM=<kdm> -DKDM_VERIFY_THREADS=<n> -DKDM_VERIFY_ARGS=<option>|<option>...]
#         -P KdmBakeStep.cmake
if(DEFINED KDM_VERIFY_KDM)
  string(REPLACE "|" ";" extra "${KDM_VERIFY_ARGS}")
  execute_process(COMMAND "${KDM_VERIFY_KDM}" verify --quiet --threads "${KDM_VERIFY_THREADS}" ${extra}
                          "${KDM_BAKE_SCRATCH}"
                  RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    file(REMOVE "${KDM_BAKE_SCRATCH}")
    message(FATAL_ERROR "kdm verify did not pass ${KDM_BAKE_SCRATCH} (${result}): the set is not kept")
  endif()
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -E compare_files "${KDM_BAKE_SCRATCH}" "${KDM_BAKE_OUTPUT}"
                RESULT_VARIABLE differs OUTPUT_QUIET ERROR_QUIET)
if(differs EQUAL 0)
  file(REMOVE "${KDM_BAKE_SCRATCH}")
else()
  file(RENAME "${KDM_BAKE_SCRATCH}" "${KDM_BAKE_OUTPUT}")  # atomic: never a partial set
endif()
file(TOUCH "${KDM_BAKE_STAMP}")
