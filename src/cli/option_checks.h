#pragma once
// Validators for the command's options, worded for a user: "'0.2cm' is not a
// number", "must be > 0 (got 0)", "'bogus' is not one of none, icp or lum".
// CLI11's own print its internal ranges (1.8e308 in full) and enum tables.

#include <obsgroup/common/enum_names.h>

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>

namespace obsgroup::cli {

/// A number as a user wrote it: 1, 0.7, 1e-06.
inline std::string number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// A finite number in [low, high]; `low_open` makes the lower bound strict.
inline CLI::Validator finiteNumber(double low, bool low_open = false,
                                   double high = std::numeric_limits<double>::infinity()) {
  const auto bound = number;
  std::string range;
  if (std::isinf(high))
    range = std::string(low_open ? "> " : ">= ") + bound(low);
  else
    range = "between " + bound(low) + " and " + bound(high);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
          return "'" + text + "' is not a number";
        if (!std::isfinite(v)) return "'" + text + "' is not a finite number";
        if (v < low || (low_open && v == low) || v > high) return "must be " + range + " (got " + text + ")";
        return "";
      },
      "", "number");
}

/// A whole number >= low.
inline CLI::Validator wholeNumber(long long low) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        errno = 0;
        char* end = nullptr;
        const long long v = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
          return "'" + text + "' is not a whole number";
        if (v < low || v > (1LL << 30)) return "must be between " + std::to_string(low) + " and 1073741824 (got " + text + ")";
        return "";
      },
      "", "whole number");
}

/// One of the names of an enum's table (common/enum_names.h); the option
/// then receives its value.
template <typename Enum, std::size_t N>
CLI::Validator oneOf(const EnumName<Enum> (&table)[N]) {
  return CLI::Validator(
      [&table](std::string& text) -> std::string {
        for (const auto& entry : table)
          if (text == entry.name) {
            text = std::to_string(static_cast<long long>(entry.value));
            return "";
          }
        return "'" + text + "' is not one of " + namesOf(table);
      },
      "", "name");
}

/// "none|icp|lum", shown in --help where CLI11 would print ENUM and a table.
template <typename Enum, std::size_t N>
std::string choices(const EnumName<Enum> (&table)[N]) {
  std::string text;
  for (const auto& entry : table) text += (text.empty() ? "" : "|") + std::string(entry.name);
  return text;
}

}  // namespace obsgroup::cli
