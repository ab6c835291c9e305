#pragma once
// `stentsim init`: writes a commented, runnable example case for a scene.
#include <filesystem>
#include <map>
#include <string>

namespace stentsim::workflows {

/// The example files shipped in examples/, embedded at build time.
const std::map<std::string, std::string>& embedded_examples();

/// Writes the example case for `scene` into `dir` as <scene>.yaml and returns
/// its path. Refuses to overwrite an existing file.
std::filesystem::path write_example_case(const std::filesystem::path& dir, const std::string& scene);

}  // namespace stentsim::workflows
