#pragma once

#include <stdexcept>
#include <string>

namespace sonarbench {

/// Bad input the user must fix: a file, a YAML key or value, a log. The message names the file,
/// the key or line, and what was expected. The CLI maps it to exit status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace sonarbench
