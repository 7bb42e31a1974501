#pragma once
// Errors at the input edge carry the file and the JSON pointer of the fault, so that the command
// line can answer with one line: "error: plan.json: /placements/3/joints: expected 2 numbers, got
// 3".

#include <stdexcept>
#include <string>

namespace artcal {

/// An error at a place of an input: the file and the JSON pointer (or CSV line) of the fault.
class LocatedError : public std::runtime_error {
 public:
  LocatedError(std::string file, std::string pointer, const std::string& message)
      : std::runtime_error(message), file_(std::move(file)), pointer_(std::move(pointer)) {}

  const std::string& file() const { return file_; }
  /// JSON pointer of the offending value ("" for the whole document).
  const std::string& pointer() const { return pointer_; }
  /// "FILE: POINTER: MESSAGE" (the pointer is left out when empty).
  std::string describe() const {
    std::string out = file_;
    if (!pointer_.empty()) out += ": " + pointer_;
    return out + ": " + what();
  }

 private:
  std::string file_;
  std::string pointer_;
};

/// Bad input: the command line maps it to exit status 2.
class InputError : public LocatedError {
 public:
  using LocatedError::LocatedError;
};

/// A numerical failure of a model (forward kinematics that did not converge, a singular
/// configuration). Numerical code raises it; the edge (io, command line) says where it happened.
class KinematicsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A valid plan that cannot be run as asked: a simulated machine (simulate, confirm) that cannot
/// reach a planned reading. It names the place like InputError, but the command line answers with
/// exit status 1, not 2: the plan is not bad input, the run failed (docs/plan-format.md).
class RunError : public LocatedError {
 public:
  using LocatedError::LocatedError;
  /// The same error with `context` ("trial 17") put before the message.
  RunError within(const std::string& context) const {
    return {file(), pointer(), context + ": " + what()};
  }
};

}  // namespace artcal
