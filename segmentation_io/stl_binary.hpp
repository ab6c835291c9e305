#pragma once
// Binary STL by the size rule: 80-byte header, a 32-bit triangle count n, then
// n records of 50 bytes (normal, three vertices as float32, a 16-bit
// attribute). A file of exactly 84 + 50 n bytes is binary whatever its header
// says (many exporters start binary headers with "solid"); VTK's reader tells
// the two kinds apart by the first bytes only and reads a file cut short as a
// shorter surface without a word.
#include <filesystem>
#include <optional>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

/// The surface of a binary STL file, or nothing when the file is ASCII STL
/// ("solid" followed by text). InputError naming the file when it is neither,
/// or shorter than its triangle count needs (cut short); a longer one is read
/// with a warning. Vertices that repeat exactly are merged (STL stores each
/// vertex once per facet). Never allocates from the count before the size
/// confirms it.
std::optional<TriSurface> read_binary_stl(const std::filesystem::path& file);

}  // namespace stentsim::segmentation
