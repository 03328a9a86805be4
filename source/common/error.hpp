#pragma once
// Errors a user can act on. InputError is thrown for bad scene files and stops the run before the
// first step; the message names the key, the value given and what is allowed.
#include <stdexcept>
#include <string>

namespace cfdmpm {

class InputError : public std::runtime_error {
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
