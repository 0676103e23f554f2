#pragma once
// fleetmap's small exception hierarchy. Misuse and bad input throw; expected outcomes
// ("no path", "no reliable overlap") are return values, never exceptions.
#include <stdexcept>
#include <string>

namespace fleetmap {

// Base of every fleetmap exception. The message is one line meant for a user.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad input from a user: a file, a key, a value. The message names the input and the problem,
// e.g. "maps/x.yaml: key 'resolution': expected a positive number, got '-1'".
class InputError : public Error {
 public:
  using Error::Error;
};

}  // namespace fleetmap
