#pragma once
/// \file
/// The error of an observation the method cannot use. No PCL here: the grid
/// back-end throws it too.

#include <stdexcept>
#include <string>

namespace obsgroup {

/// An observation the method cannot use (a null cloud, a non-finite pose, a
/// point too far from the others for the grid), naming which one, so that a
/// caller can point at the file or log line it came from.
class InvalidObservation : public std::invalid_argument {
 public:
  InvalidObservation(int index, const std::string& reason)
      : std::invalid_argument("observation " + std::to_string(index) + ": " + reason), index_(index) {}
  /// Position of the observation in the input.
  int index() const { return index_; }

 private:
  int index_;
};

}  // namespace obsgroup
