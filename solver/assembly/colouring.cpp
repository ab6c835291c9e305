#include "solver/assembly/colouring.hpp"

#include <stdexcept>

namespace stentsim::solver {

std::vector<std::vector<std::uint32_t>> colour_by_nodes(std::size_t n, std::size_t num_nodes,
                                                        const std::function<std::span<const std::int64_t>(std::size_t)>& nodes_of) {
  // Per node a bit mask of the colours its elements have, in 64-colour words; a
  // tet10 vertex has some 20-70 elements, so one or two words.
  std::size_t words = 1;
  std::vector<std::uint64_t> used(num_nodes * words, 0);
  std::vector<std::vector<std::uint32_t>> colours;
  std::vector<std::uint64_t> taken;
  for (std::size_t i = 0; i < n; ++i) {
    const auto nodes = nodes_of(i);
    taken.assign(words, 0);
    for (const std::int64_t a : nodes) {
      if (a < 0 || static_cast<std::size_t>(a) >= num_nodes) throw std::out_of_range("colour_by_nodes: node index out of range");
      for (std::size_t w = 0; w < words; ++w) taken[w] |= used[static_cast<std::size_t>(a) * words + w];
    }
    std::size_t c = 0;
    while (c < 64 * words && (taken[c / 64] >> (c % 64) & 1u)) ++c;
    if (c == 64 * words) {
      // Every colour so far is taken here: widen the masks by a word.
      std::vector<std::uint64_t> wider(num_nodes * (words + 1), 0);
      for (std::size_t a = 0; a < num_nodes; ++a)
        for (std::size_t w = 0; w < words; ++w) wider[a * (words + 1) + w] = used[a * words + w];
      used.swap(wider);
      ++words;
    }
    for (const std::int64_t a : nodes) used[static_cast<std::size_t>(a) * words + c / 64] |= std::uint64_t{1} << (c % 64);
    if (c >= colours.size()) colours.resize(c + 1);
    colours[c].push_back(static_cast<std::uint32_t>(i));
  }
  return colours;
}

}  // namespace stentsim::solver
