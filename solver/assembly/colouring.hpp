#pragma once
// Greedy colouring of elements by shared nodes: no two elements of one colour
// share a node, so a colour's element blocks scatter into disjoint rows of the
// global system and may be added from several threads at once. The colours
// and the order inside each are a function of the mesh alone, so a coloured
// loop sums every matrix entry in the same order whatever the thread count.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace stentsim::solver {

/// Colours items 0..n-1 whose nodes `nodes_of(i)` gives (node indices below
/// `num_nodes`); each colour lists its items in increasing order. Greedy in item
/// order: an item takes the lowest colour none of its nodes has yet.
std::vector<std::vector<std::uint32_t>> colour_by_nodes(std::size_t n, std::size_t num_nodes,
                                                        const std::function<std::span<const std::int64_t>(std::size_t)>& nodes_of);

}  // namespace stentsim::solver
