#pragma once
/// \file
/// What the evaluation programs share to write their results pages.

#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace obsgroup::examples {

/// Replaces the lines between "<!-- generated:begin -->" and
/// "<!-- generated:end -->" of `file` with `report`, keeping the rest; a
/// page with more than one generated section names them:
/// "<!-- generated:NAME:begin -->" ... "<!-- generated:NAME:end -->".
/// Returns 0, or 3 (with a message) when the file has no such section.
inline int writeGeneratedSection(const std::string& file, const std::string& report, const std::string& name = "") {
  std::ifstream in(file);
  std::stringstream existing;
  existing << in.rdbuf();
  const std::string text = existing.str();
  const std::string tag = name.empty() ? "generated:" : "generated:" + name + ":";
  const std::string begin = "<!-- " + tag + "begin -->\n", end = "<!-- " + tag + "end -->";
  const std::size_t b = text.find(begin), e = text.find(end);
  if (b == std::string::npos || e == std::string::npos || e < b) {
    std::cerr << "error: " << file << ": no '" << begin.substr(0, begin.size() - 1) << "' ... '" << end
              << "' section\n";
    return 3;
  }
  std::ofstream(file) << text.substr(0, b + begin.size()) << report << text.substr(e);
  std::cout << "updated " << file << "\n";
  return 0;
}

/// "a,b,c" as {"a", "b", "c"}; empty items are dropped.
inline std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

}  // namespace obsgroup::examples
