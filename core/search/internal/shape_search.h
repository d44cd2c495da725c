// The search from the query's whole shape (SeedSelection::kShapeWindows, issue 39 item 3):
// candidate ranges from the library windows whose shapes, at the query's length and at lengths
// either side, are nearest the query's (LibraryIndex::NearestShapes), re-ranked by the exact
// search's subsequence warp over those ranges alone (core/search/internal/clip_scan.h). With
// refinement (SearchParams::refine) the ranges are warped at about 15 Hz, as the fast search's
// seeds are, and the best coarse warps settled at the full rate by the same scan over their own
// frames and a margin: a result is the best full-rate warp there. Without, a result is the best
// warp inside its range, and when the ranges cover the library, the results are the exact
// search's.
#ifndef MOTIONDB_CORE_SEARCH_INTERNAL_SHAPE_SEARCH_H_
#define MOTIONDB_CORE_SEARCH_INTERNAL_SHAPE_SEARCH_H_

#include "absl/status/statusor.h"
#include "core/index/coordinate_view.h"
#include "core/index/library_index.h"
#include "core/search/internal/search_query.h"
#include "core/search/search_params.h"
#include "core/search/search_result.h"

namespace motiondb {

// The search of `query` (two frames or more) in what `filter` admits. Search() calls it with a
// query and parameters PrepareQuery checked, which it assumes. Stats: seeds are the windows
// found, clusters the ranges re-ranked (one clip's overlapping ranges merged), warps the ranges
// that gave a result (at the coarse rate with refinement), cells the warps' (the settling's
// included, its time refine_ms). Thread-safe, as Search().
absl::StatusOr<SearchResponse> ShapeSearch(const LibraryIndex& library, CoordinateView query,
                                           const SearchFilter& filter, const SearchParams& params);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SEARCH_INTERNAL_SHAPE_SEARCH_H_
