#pragma once
// Why a stage must run: never run, failed, version or configuration changed,
// an input's content changed, an output missing or modified.
#include <string>
#include <vector>

#include "pipeline/manifest.hpp"
#include "pipeline/plan.hpp"

namespace stentsim::pipeline {

/// Reasons stage `i` is stale given the files on disk now; empty when up to date.
std::vector<std::string> stale_reasons(const Plan& plan, std::size_t i, const Manifest& manifest);

/// Content hashes of a stage's inputs as they are now (missing files are "missing").
std::map<std::string, std::string> hash_inputs(const Plan& plan, std::size_t i);
/// Content hashes of a stage's outputs as they are now.
std::map<std::string, std::string> hash_outputs(const Plan& plan, std::size_t i);

}  // namespace stentsim::pipeline
