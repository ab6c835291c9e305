#pragma once
// File names inside a study's inputs. A base scene or case names its mesh,
// fiber or lumen file relative to itself (stentsim's readers resolve a
// relative path against the folder of the file that holds it); a study runs
// a copy of it in the run's own folder, where that name means nothing. So
// before a copy is written, every relative text value that names an existing
// file beside its origin (the base file, or the study file for `overrides`
// and knob values) becomes that file's absolute path. Values that name no
// existing file (element types, presets, output folders) stay as they are.
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace stentsim::study {

/// Rewrites, in place, every relative scalar of `node` (at any depth) that
/// names an existing regular file relative to `folder` into its absolute,
/// normalised path. Returns the files it rewrote.
std::vector<std::filesystem::path> resolve_relative_files(YAML::Node node, const std::filesystem::path& folder);

/// Every absolute path to an existing regular file among the scalars of
/// `node`, sorted: the files a run reads, whose content is part of its key.
std::vector<std::filesystem::path> referenced_files(const YAML::Node& node);

/// Content hashes of files, computed once per file.
class FileHashes {
 public:
  const std::string& of(const std::filesystem::path& file);

 private:
  std::map<std::filesystem::path, std::string> hashes_;
};

}  // namespace stentsim::study
