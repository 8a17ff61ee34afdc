#pragma once
/// \file
/// The one table of names of each enum that users name (in options, in
/// partition.json): toString, the *FromString functions and the command's
/// option parsing all read it, so a name can only be spelt one way.

#include <cstddef>
#include <stdexcept>
#include <string>

namespace obsgroup {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

/// The name of `value` in `table`, or "?" for a value outside it.
template <typename Enum, std::size_t N>
std::string nameOf(const EnumName<Enum> (&table)[N], Enum value) {
  for (const auto& entry : table)
    if (entry.value == value) return entry.name;
  return "?";
}

/// "a, b or c": the names of `table`, for messages and help.
template <typename Enum, std::size_t N>
std::string namesOf(const EnumName<Enum> (&table)[N]) {
  std::string list;
  for (std::size_t k = 0; k < N; ++k) list += (k == 0 ? "" : k + 1 == N ? " or " : ", ") + std::string(table[k].name);
  return list;
}

/// The value named `name`; throws std::invalid_argument naming `what` and
/// the names it knows otherwise.
template <typename Enum, std::size_t N>
Enum valueNamed(const EnumName<Enum> (&table)[N], const std::string& name, const char* what) {
  for (const auto& entry : table)
    if (name == entry.name) return entry.value;
  throw std::invalid_argument("unknown " + std::string(what) + " '" + name + "' (expected " + namesOf(table) + ")");
}

}  // namespace obsgroup
