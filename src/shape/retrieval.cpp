#include "geods/shape/retrieval.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "geods/core/error.hpp"
#include "geods/core/parallel.hpp"

namespace geods::shape {

void score_ranking(const std::vector<bool>& relevant, std::size_t class_size, RetrievalScores& s) {
  const std::size_t r = class_size - 1, n = relevant.size();
  if (r == 0) return;
  std::size_t hits = 0, first = 0, second = 0, at_k = 0;
  double ap = 0;
  std::vector<double> precision_at_hit;  // precision when the j-th relevant one is reached
  for (std::size_t i = 0; i < n; ++i) {
    if (!relevant[i]) continue;
    ++hits;
    if (i < r) ++first;
    if (i < 2 * r) ++second;
    if (i < s.k) ++at_k;
    precision_at_hit.push_back(double(hits) / double(i + 1));
    ap += precision_at_hit.back();
  }
  s.nn_rate += n > 0 && relevant[0] ? 1.0 : 0.0;
  s.precision_at_k += double(at_k) / double(s.k);
  s.first_tier += double(first) / double(r);
  s.second_tier += double(second) / double(r);
  s.mean_average_precision += ap / double(r);
  // Interpolated precision: the best precision at recall >= level.
  for (std::size_t l = 0; l < s.recall.size(); ++l) {
    const double level = s.recall[l];
    double best = 0;
    for (std::size_t j = 0; j < precision_at_hit.size(); ++j)
      if (double(j + 1) / double(r) >= level - 1e-12) best = std::max(best, precision_at_hit[j]);
    s.precision[l] += best;
  }
}

RetrievalScores evaluate_retrieval(const ShapeDatabase& db, std::size_t k, std::size_t recall_levels) {
  if (k == 0) throw Error("evaluate_retrieval: k must be >= 1");
  if (recall_levels == 0) throw Error("evaluate_retrieval: recall_levels must be >= 1");
  const auto start = std::chrono::steady_clock::now();
  RetrievalScores total;
  total.shapes = db.size();
  total.k = k;
  for (std::size_t l = 1; l <= recall_levels; ++l) total.recall.push_back(double(l) / double(recall_levels));
  total.precision.assign(recall_levels, 0.0);

  std::map<std::string, std::size_t> class_size;
  for (const std::string& label : db.labels())
    if (!label.empty()) ++class_size[label];
  std::vector<std::uint64_t> queries;
  for (std::uint64_t id = 0; id < db.size(); ++id)
    if (!db.label(id).empty() && class_size[db.label(id)] >= 2) queries.push_back(id);
  for (const auto& [label, count] : class_size) total.classes += count >= 2;
  total.queries = queries.size();

  std::vector<RetrievalScores> partial(queries.size());
  parallel_for(0, queries.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t q = b; q < e; ++q) {
      const std::uint64_t id = queries[q];
      RetrievalScores& s = partial[q];
      s.k = k;
      s.recall = total.recall;
      s.precision.assign(recall_levels, 0.0);
      std::vector<bool> relevant;
      relevant.reserve(db.size());
      for (const ShapeMatch& m : db.query_descriptor(db.descriptor(id), db.size()))
        if (m.id != id) relevant.push_back(m.label == db.label(id));
      score_ranking(relevant, class_size.at(db.label(id)), s);
    }
  });
  for (const RetrievalScores& s : partial) {  // in query order: deterministic sums
    total.nn_rate += s.nn_rate;
    total.precision_at_k += s.precision_at_k;
    total.first_tier += s.first_tier;
    total.second_tier += s.second_tier;
    total.mean_average_precision += s.mean_average_precision;
    for (std::size_t l = 0; l < recall_levels; ++l) total.precision[l] += s.precision[l];
  }
  if (!queries.empty()) {
    const double n = double(queries.size());
    total.nn_rate /= n;
    total.precision_at_k /= n;
    total.first_tier /= n;
    total.second_tier /= n;
    total.mean_average_precision /= n;
    for (double& p : total.precision) p /= n;
  }
  total.compute_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return total;
}

}  // namespace geods::shape
