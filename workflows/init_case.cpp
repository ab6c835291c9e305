#include "workflows/init_case.hpp"

#include <fmt/format.h>

#include "common/error.hpp"
#include "common/files.hpp"

namespace stentsim::workflows {

std::filesystem::path write_example_case(const std::filesystem::path& dir, const std::string& scene) {
  const auto& examples = embedded_examples();
  auto it = examples.find(scene + ".yaml");
  if (it == examples.end())
    throw InputError(fmt::format("init: no example named '{}'; scenes: free-expansion, generic-artery, patient", scene));
  const auto target = dir / it->first;
  if (std::filesystem::exists(target))
    throw InputError(fmt::format("{}: already exists; init does not overwrite files", target.string()));
  files::write_atomic(target, it->second);
  return target;
}

}  // namespace stentsim::workflows
