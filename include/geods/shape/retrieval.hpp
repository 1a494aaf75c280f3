#pragma once
// Retrieval quality of a labelled shape database, with the measures of the
// Princeton Shape Benchmark (Shilane, Min, Kazhdan, Funkhouser 2004): every
// labelled shape whose class has another member queries the database; the
// others are ranked by distance (the query itself left out) and scored against
// its class of C members:
//   nearest-neighbor rate  the nearest is of the class (averaged over queries);
//   precision at k         fraction of the k nearest of the class;
//   first tier             fraction of the class among the C - 1 nearest (recall at C - 1);
//   second tier            fraction of the class among the 2 (C - 1) nearest;
//   precision-recall       precision at recall 1/R, 2/R, ..., 1 (R levels),
//                          interpolated (the best precision at that recall or beyond);
//   mean average precision the mean over queries of the precision at each relevant match.
// Unlabelled shapes (empty label) are ranked but never query or count as relevant.
#include <cstddef>
#include <vector>

#include "geods/shape/shape_database.hpp"

namespace geods::shape {

struct RetrievalScores {
  std::size_t shapes = 0;   // in the database
  std::size_t queries = 0;  // labelled shapes whose class has >= 2 members
  std::size_t classes = 0;  // distinct labels with >= 2 members
  std::size_t k = 0;
  double nn_rate = 0, precision_at_k = 0, first_tier = 0, second_tier = 0, mean_average_precision = 0;
  std::vector<double> recall, precision;  // the precision-recall curve
  double compute_s = 0;
};

/// Scores every query (in parallel) by an exact ranking of all shapes
/// (the database's k-d tree with k = size()); O(n^2 log n) for n shapes.
/// Throws geods::Error for k == 0 or recall_levels == 0.
RetrievalScores evaluate_retrieval(const ShapeDatabase& db, std::size_t k = 5, std::size_t recall_levels = 20);

/// The measures of one ranked list: `relevant[i]` says whether the i-th
/// nearest (the query excluded) is of the query's class, of `class_size`
/// members (the query included). Adds to `scores` (unnormalized sums).
void score_ranking(const std::vector<bool>& relevant, std::size_t class_size, RetrievalScores& scores);

}  // namespace geods::shape
