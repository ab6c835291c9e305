#include "workflows/study/input_paths.hpp"

#include <algorithm>

#include "common/files.hpp"

namespace fs = std::filesystem;

namespace stentsim::study {
namespace {

bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

template <class Visit>
void each_scalar(YAML::Node node, const Visit& visit) {
  if (node.IsScalar()) {
    visit(node);
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) each_scalar(node[i], visit);
  } else if (node.IsMap()) {
    for (auto kv : node) each_scalar(kv.second, visit);
  }
}

}  // namespace

std::vector<fs::path> resolve_relative_files(YAML::Node node, const fs::path& folder) {
  std::vector<fs::path> out;
  const fs::path base = fs::absolute(folder);
  each_scalar(node, [&](YAML::Node s) {
    const std::string& text = s.Scalar();
    if (text.empty() || text.find('\n') != std::string::npos) return;
    const fs::path p(text);
    if (!p.is_relative() || !is_file(base / p)) return;
    const fs::path resolved = (base / p).lexically_normal();
    s = resolved.string();
    out.push_back(resolved);
  });
  return out;
}

std::vector<fs::path> referenced_files(const YAML::Node& node) {
  std::vector<fs::path> out;
  each_scalar(YAML::Clone(node), [&](YAML::Node s) {
    const fs::path p(s.Scalar());
    if (p.is_absolute() && is_file(p)) out.push_back(p);
  });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

const std::string& FileHashes::of(const fs::path& file) {
  auto it = hashes_.find(file);
  if (it == hashes_.end()) it = hashes_.emplace(file, files::content_hash(file)).first;
  return it->second;
}

}  // namespace stentsim::study
