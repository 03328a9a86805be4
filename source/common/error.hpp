#pragma once
// Errors a user can act on. InputError is thrown for bad scene files and stops the run before the
// first step; the message names the key, the value given and what is allowed. StepFailure is thrown
// by a time step that went wrong in a way a smaller time step may cure.
#include <stdexcept>
#include <string>

namespace cfdmpm {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A time step that failed: values that are not finite, a pressure solve that did not converge, an
/// outflux larger than a cell, an inverted particle. Thrown on every rank with the same message,
/// which names the cell or particle, the material and the quantity; the driver undoes the step and
/// retries it with half the time step (mpmice/simulation.cpp).
class StepFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Builds the standard message: "<key>: got '<value>'; <allowed>".
inline InputError inputError(const std::string& key, const std::string& value,
                             const std::string& allowed)
{
  return InputError(key + ": got '" + value + "'; " + allowed);
}

}  // namespace cfdmpm
