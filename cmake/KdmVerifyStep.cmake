# kdm_bake_tileset's VERIFY step: runs `kdm verify` on the freshly baked scratch file and removes it when a
# check fails, so that a failed step leaves no file behind.
#   cmake -DKDM_VERIFY_KDM=<kdm> -DKDM_VERIFY_FILE=<scratch> -DKDM_VERIFY_THREADS=<n>
#         [-DKDM_VERIFY_ARGS=<option>|<option>...] -P KdmVerifyStep.cmake
string(REPLACE "|" ";" extra "${KDM_VERIFY_ARGS}")
execute_process(COMMAND "${KDM_VERIFY_KDM}" verify --quiet --threads "${KDM_VERIFY_THREADS}" ${extra}
                        "${KDM_VERIFY_FILE}"
                RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  file(REMOVE "${KDM_VERIFY_FILE}")
  message(FATAL_ERROR "kdm verify did not pass ${KDM_VERIFY_FILE} (${result}): the set is not kept")
endif()
