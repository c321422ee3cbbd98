#include "kdm/runtime/version.h"

#include "kdm_version_config.h"

namespace kdm {

const char* version_string() {
  return KDM_VERSION_STRING;
}

std::uint32_t version_number() {
  return KDM_VERSION_NUMBER;
}

}  // namespace kdm
