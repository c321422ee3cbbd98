// Internal: query_points with the count of candidates examined carried in and out, so that a caller
// running it in pieces (query_classes, a chunk at a time) keeps one call's bound on its work.
#pragma once

#include <cstddef>
#include <cstdint>

#include "kdm/runtime/query.h"

namespace kdm::detail {

/// query_points, counting into `examined` (on entry, what this call of the caller has examined so far):
/// it returns kBufferFull once `examined` reaches kMaxQueryCandidates.
Status query_points_counted(const Tileset& tileset, const QueryParams& params, QueryPoint* out,
                            std::size_t capacity, std::size_t* written, QueryCursor* cursor,
                            QueryProblem* problem, std::uint64_t& examined);

}  // namespace kdm::detail
