#pragma once
// Errors the user can act on. Every message names the file, the field and
// what was expected (DESIGN.md §7); the CLI prints it and exits non-zero.
#include <new>
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

/// The message for an exception that is none of the above (a library's, the standard
/// library's): worded for the user, never the bare text of std::bad_alloc ("std::bad_alloc")
/// or of a failed bounds check. Used wherever a command or a stage ends on one.
inline std::string describe_unexpected(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e))
    return "out of memory: this input needs more memory than the process could get (a mesh, an image or a count far larger "
           "than expected? check the sizes in the input, or run on a machine with more memory)";
  // stentsim's own errors (a ComputeError reaches the callers' std::exception handler) are worded already.
  if (dynamic_cast<const InputError*>(&e) || dynamic_cast<const ComputeError*>(&e)) return e.what();
  return std::string("internal error (please report it with the input that caused it): ") + e.what();
}

/// The message for something thrown that is not an exception at all.
inline std::string describe_unknown() { return "internal error (please report it with the input that caused it): an unknown exception"; }

}  // namespace stentsim
