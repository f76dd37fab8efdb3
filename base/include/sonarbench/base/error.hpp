#pragma once

#include <stdexcept>

namespace sonarbench {

/// Bad input the user must fix: a file, a YAML key or value, a log. The message names the file,
/// the key or line, and what was expected. The CLI maps it to exit status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The machine refused what the user asked of it: a read-only or full disk, no permission. The
/// message names the path and gives the OS's reason; exit status 2 as for bad input.
class EnvironmentError : public InputError {
 public:
  using InputError::InputError;
};

}  // namespace sonarbench
