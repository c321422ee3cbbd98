// What every runtime call returns: one code per way a load, a save or a query can end.
#pragma once

#include "kdm/runtime/export.h"

namespace kdm {

/// Result of reading or writing a tile set, building a density's tables, or a query. Every failure has its
/// own code.
enum class Status : int {
  kOk = 0,
  kIoError,                  ///< the file could not be opened, read, written or renamed
  kBadMagic,                 ///< not a kdm tile set
  kUnsupportedVersion,       ///< written by an incompatible format version
  kTruncated,                ///< shorter than its header says (or than a header)
  kTrailingBytes,            ///< longer than its header says
  kHeaderChecksumMismatch,   ///< header bytes damaged
  kPayloadChecksumMismatch,  ///< payload bytes damaged
  kTooLarge,                 ///< a size exceeds the reader's caps (kMax* in tileset_format.h)
  kDecompressionFailed,      ///< the payload is not a valid zstd frame of the stated size
  kInvalidContent,           ///< checksums match but the content is inconsistent (hostile or buggy writer)
  kInvalidArgument,          ///< a caller-side error (e.g. saving an inconsistent TilesetData)
  kBufferFull,               ///< a query filled the caller's buffer, or examined its most candidates in one
                             ///< call (kMaxQueryCandidates): resume with the same cursor; a parallel
                             ///< query's output was too small: call again with room for the count given
  kOutOfMemory,              ///< an allocation failed (a tile set's, through its allocator hook too, an
                             ///< image's, a class-image sum's or a parallel query's scratch)
};

/// A short English description of `status` (static storage).
KDM_RUNTIME_API const char* status_message(Status status);

}  // namespace kdm
