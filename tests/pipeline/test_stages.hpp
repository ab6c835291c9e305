#pragma once
// Test-only stages for the runner tests (never part of the product): each
// concatenates its inputs plus its config into its output and appends a line
// to a counter file so tests can see how often it ran (stages run in child
// processes, so in-memory counters would not work).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <new>
#include <string>
#include <vector>
#include <thread>

#include "common/error.hpp"
#include "common/files.hpp"
#include "pipeline/stage.hpp"

namespace stentsim::testing {

inline int run_count(const std::filesystem::path& counters, const std::string& stage) {
  std::ifstream in(counters / stage);
  int n = 0;
  std::string line;
  while (std::getline(in, line)) ++n;
  return n;
}

/// A stage `name` reading `inputs`, writing `output`. Its config may contain
/// the words "fail", "crash" or "sleep" to fail, abort or sleep 30 s ("oom", "bounds", "throw int": std::bad_alloc, a failed bounds check, a non-exception); "halfway"
/// writes its output and then fails.
inline pipeline::Stage concat_stage(const std::string& name, std::vector<std::string> inputs, const std::string& output,
                                    const std::string& config, const std::filesystem::path& counters) {
  pipeline::Stage s;
  s.name = name;
  s.inputs = std::move(inputs);
  s.outputs = {output};
  s.config = config;
  s.run = [name, output, config, counters](pipeline::StageContext& ctx) {
    std::filesystem::create_directories(counters);
    std::ofstream(counters / name, std::ios::app) << "ran\n";
    if (config.find("sleep") != std::string::npos) std::this_thread::sleep_for(std::chrono::seconds(30));
    // "barrier": wait (up to 20 s) until every stage named in the counters'
    // barrier folder has arrived; passes only if the stages run concurrently.
    if (config.find("barrier") != std::string::npos) {
      const auto dir = counters / "barrier";
      std::filesystem::create_directories(dir);
      std::ofstream(dir / name) << "here\n";
      for (int i = 0; i < 2000; ++i) {
        int n = 0;
        for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(dir)) ++n;
        if (n >= 2) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      int n = 0;
      for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(dir)) ++n;
      if (n < 2) throw InputError("barrier: the other stage never ran at the same time");
    }
    if (config.find("partial") != std::string::npos) {
      // Writes its first output only, then "forgets" the second.
      files::write_atomic(ctx.output(output), "partial\n");
      return;
    }
    if (config.find("crash") != std::string::npos) std::abort();
    if (config.find("oom") != std::string::npos) throw std::bad_alloc();
    if (config.find("bounds") != std::string::npos) (void)std::vector<int>().at(3);
    if (config.find("throw int") != std::string::npos) throw 42;
    if (config.find("halfway") != std::string::npos) {
      // Writes what a solve that diverged leaves (its last frame), then fails.
      files::write_atomic(ctx.output(output), "last converged\n");
      throw ComputeError("deliberate failure of " + name + " halfway");
    }
    if (config.find("fail") != std::string::npos) throw InputError("deliberate failure of " + name);
    std::string text;
    for (const auto& in : ctx.stage().inputs) text += files::read_text(ctx.input(in));
    text += name + ":" + config + "\n";
    files::write_atomic(ctx.output(output), text);
    ctx.summary().set("length", static_cast<double>(text.size()), "byte");
  };
  return s;
}

}  // namespace stentsim::testing
