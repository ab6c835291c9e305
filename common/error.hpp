#pragma once
// Errors the user can act on. Every message names the file, the field and
// what was expected (DESIGN.md §7); the CLI prints it and exits non-zero.
#include <stdexcept>
#include <string>

namespace stentsim {

/// Bad input: a file or field that does not hold what it should.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A computation that could not complete (divergence, bad geometry, ...).
class ComputeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The user interrupted (Ctrl-C / SIGTERM).
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

}  // namespace stentsim
