// Status codes' messages (kdm/runtime/status.h).
#include "kdm/runtime/status.h"

namespace kdm {

const char* status_message(Status status) {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kIoError:
      return "I/O error";
    case Status::kBadMagic:
      return "not a kdm tile set (bad magic)";
    case Status::kUnsupportedVersion:
      return "unsupported tile-set format version";
    case Status::kTruncated:
      return "tile set is truncated";
    case Status::kTrailingBytes:
      return "tile set has trailing bytes";
    case Status::kHeaderChecksumMismatch:
      return "tile-set header checksum mismatch";
    case Status::kPayloadChecksumMismatch:
      return "tile-set payload checksum mismatch";
    case Status::kTooLarge:
      return "tile set exceeds the reader's size limits";
    case Status::kDecompressionFailed:
      return "tile-set payload does not decompress";
    case Status::kInvalidContent:
      return "tile-set content is inconsistent";
    case Status::kInvalidArgument:
      return "invalid argument";
    case Status::kBufferFull:
      return "output buffer full, or the call's work bound reached: resume with the same cursor (a parallel "
             "query: give it room for the count it returned)";
    case Status::kOutOfMemory:
      return "out of memory";
  }
  return "unknown status";
}

}  // namespace kdm
