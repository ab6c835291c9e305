#pragma once
// `stentsim study stability [SUITE.yaml] [--out DIR] [--subset quick|all]
// [--cases ID,...] [--binary PATH]` (issue 11): runs the stability suite
// (default examples/studies/stability/stability.yaml, looked up from the
// current folder and from the executable's folder upwards) and writes
// stability.csv and stability.md into DIR (default: <suite>.work beside the
// suite file). Exit codes: 0 every case as expected, 1 some case not,
// 2 bad input (suite file, command line).
#include <string>
#include <vector>

namespace stentsim::study {

/// `args` are the words after `study stability`. Prints progress to stdout
/// and errors to stderr; returns the exit code.
int run_stability_command(const std::vector<std::string>& args);

}  // namespace stentsim::study
