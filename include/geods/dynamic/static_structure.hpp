#pragma once
// What a static structure must provide to be dynamized (seed §7.1, Figure 69).
//
// The seed's TStat offers build(V, D), query(V, q), extract(V, D) and erase(V),
// and optionally weak.delete(V, d). Here items are addressed by their *slot*:
// build(items) puts items[i] in slot i, queries report slots, extract() returns
// every item in slot order and weak_delete(slot) hides one slot from queries
// while it stays stored. Erase is the destructor. The dynamic wrapper keeps the
// slot -> id tables itself, so a structure never has to know about ids.
//
// Queries are not part of the concept: they must be decomposable (the answer
// over V_1 ∪ ... ∪ V_j follows from the answers over each V_i), and the wrapper
// hands each V_i to the caller, who knows how to combine answers (k nearest:
// one shared k-best list; box: the union).
#include <concepts>
#include <cstddef>
#include <vector>

namespace geods::dynamic {

/// build / size / extract, with item i of build(items) in slot i.
template <typename S>
concept StaticStructure = std::movable<S> && requires(const S& s, std::vector<typename S::Item> items) {
  typename S::Item;
  { S::build(std::move(items)) } -> std::same_as<S>;
  { s.size() } -> std::convertible_to<std::size_t>;  // slots, weakly deleted ones included
  { s.extract() } -> std::same_as<std::vector<typename S::Item>>;
};

/// A structure that can hide one slot from its queries without rebuilding
/// (seed §7.2.2); needed for deletion.
template <typename S>
concept WeakDeletable = StaticStructure<S> && requires(S& s, std::size_t slot) { s.weak_delete(slot); };

/// A structure whose build can run in bounded steps (for the worst-case variant,
/// which also gathers a build's items in steps when S offers item(slot);
/// seed §7.3): S::Builder(items) starts it, step(work) does about `work` units
/// and returns true once done, finish() completes it and hands it over;
/// estimated_work() says about how many units a whole build takes, so the
/// work can be spread evenly.
template <typename S>
concept SteppedBuild = StaticStructure<S> && requires(std::vector<typename S::Item> items, typename S::Builder& b,
                                                      std::size_t work) {
  requires std::constructible_from<typename S::Builder, std::vector<typename S::Item>>;
  { b.estimated_work() } -> std::convertible_to<std::size_t>;
  { b.step(work) } -> std::same_as<bool>;
  { b.finish() } -> std::same_as<S>;
};

}  // namespace geods::dynamic
