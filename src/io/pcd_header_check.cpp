#include "pcd_header_check.h"

#include <obsgroup/io/errors.h>
#include "text_fields.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <set>

namespace obsgroup::io {

namespace {

struct Header {
  std::size_t fields = 0;
  std::size_t point_size = 0;  // bytes per point: sum of SIZE * COUNT
  long width = -1, height = -1, points = -1;
  std::string data;
  std::size_t data_offset = 0;  // bytes before the data
};

void checkCounts(const std::vector<std::string_view>& f, const Header& h, const LineRef& where) {
  if (h.fields == 0) throw inputError(where.file, where.line, "field '" + std::string(f[0]) + "' comes before FIELDS");
  if (f.size() - 1 != h.fields)
    throw inputError(where.file, where.line,
                     "field '" + std::string(f[0]) + "' has " + std::to_string(f.size() - 1) + " values for " +
                         std::to_string(h.fields) + " FIELDS");
}

/// The first word of a line as PCL's readHeader takes it (`stream >> word`):
/// any std::isspace ends it or is skipped before it, vertical tab and form
/// feed included, where the fields of a line are split at spaces, tabs and
/// carriage returns only.
std::string_view pclKeyOf(std::string_view line) {
  const auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  std::size_t begin = 0;
  while (begin < line.size() && space(line[begin])) ++begin;
  std::size_t end = begin;
  while (end < line.size() && !space(line[end])) ++end;
  return line.substr(begin, end - begin);
}

/// PCL's readHeader does not stop at DATA: it reads on through empty and
/// comment lines, and a header key there replaces the one before, so PCL
/// would read the data with other fields than those checked here (a heap
/// overflow in fromPCLPointCloud2, and one in readBodyASCII when a vertical
/// tab hid the key from a split at spaces; both found by fuzzing). Such a
/// file is refused. The keys are looked for as PCL finds them (pclKeyOf).
void refuseHeaderAfterData(std::ifstream& in, const std::string& path, std::size_t data_line) {
  static const char* kKeys[] = {"VERSION", "FIELDS", "COLUMNS", "SIZE",   "TYPE",
                                "COUNT",   "WIDTH",  "HEIGHT",  "VIEWPOINT", "POINTS", "DATA"};
  const std::streampos start = in.tellg();
  std::string line;
  for (std::size_t number = data_line + 1; std::getline(in, line); ++number) {  // as far as PCL reads
    const std::string_view key = pclKeyOf(line);
    if (key.empty() || key.front() == '#') continue;  // PCL reads on past comments (and past more blank lines than this)
    for (const char* name : kKeys)
      if (key.substr(0, std::strlen(name)) == name)
        throw inputError(path, number, "header field '" + std::string(name) + "' after DATA: not a PCD file");
    break;
  }
  in.clear();
  in.seekg(start);
}

/// The header read so far, with the per-field lists checked against FIELDS.
struct HeaderInProgress {
  Header h;
  std::vector<long> sizes, counts;
  std::set<std::string> seen;
};

void readSizes(const std::vector<std::string_view>& f, HeaderInProgress& r, const LineRef& where) {
  checkCounts(f, r.h, where);
  for (std::size_t k = 1; k < f.size(); ++k) {
    const long s = parseCount(f[k], where, "SIZE", 8);
    if (s != 1 && s != 2 && s != 4 && s != 8)
      throw inputError(where.file, where.line, "field 'SIZE': " + std::to_string(s) + " is not 1, 2, 4 or 8");
    r.sizes.push_back(s);
  }
}

void readTypes(const std::vector<std::string_view>& f, const HeaderInProgress& r, const LineRef& where) {
  checkCounts(f, r.h, where);
  for (std::size_t k = 1; k < f.size(); ++k) {
    if (f[k] != "F" && f[k] != "I" && f[k] != "U")
      throw inputError(where.file, where.line, "field 'TYPE': '" + std::string(f[k]) + "' is not F, I or U");
    if (f[k] == "F" && k <= r.sizes.size() && r.sizes[k - 1] != 4 && r.sizes[k - 1] != 8)
      throw inputError(where.file, where.line, "field 'TYPE': F (float) with SIZE " + std::to_string(r.sizes[k - 1]) +
                                                   ": floats are 4 or 8 bytes");
  }
}

void readCounts(const std::vector<std::string_view>& f, HeaderInProgress& r, const LineRef& where) {
  checkCounts(f, r.h, where);
  for (std::size_t k = 1; k < f.size(); ++k) {
    r.counts.push_back(parseCount(f[k], where, "COUNT", 1 << 20));
    // PCL reads past the data of a field counted 0 (found by fuzzing).
    if (r.counts.back() == 0) throw inputError(where.file, where.line, "field 'COUNT': a field counted 0 holds no value");
  }
}

/// DATA ends the header: where the data start, once nothing header-like follows.
void readData(const std::vector<std::string_view>& f, Header& h, std::ifstream& in, const LineRef& where) {
  if (f.size() != 2 || (f[1] != "ascii" && f[1] != "binary" && f[1] != "binary_compressed"))
    throw inputError(where.file, where.line, "field 'DATA' must be ascii, binary or binary_compressed");
  h.data = std::string(f[1]);
  std::streampos after = in.tellg();
  if (after < 0) {  // DATA was the last line, with no newline: no data
    in.clear();
    in.seekg(0, std::ios::end);
    after = in.tellg();
  }
  h.data_offset = static_cast<std::size_t>(after);
  refuseHeaderAfterData(in, where.file, where.line);
}

/// One header line; returns false once DATA is read.
bool readHeaderLine(const std::vector<std::string_view>& f, HeaderInProgress& r, std::ifstream& in,
                    const LineRef& where) {
  const std::string key(f[0]);
  if (!r.seen.insert(key).second) throw inputError(where.file, where.line, "field '" + key + "' appears twice in the header");
  if (key == "VERSION") return true;
  if (key == "FIELDS") {
    r.h.fields = f.size() - 1;
    if (r.h.fields == 0) throw inputError(where.file, where.line, "field 'FIELDS' lists no field");
  } else if (key == "SIZE") {
    readSizes(f, r, where);
  } else if (key == "TYPE") {
    readTypes(f, r, where);
  } else if (key == "COUNT") {
    readCounts(f, r, where);
  } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
    if (f.size() != 2) throw inputError(where.file, where.line, "field '" + key + "' needs one value");
    const long v = parseCount(f[1], where, key, 1L << 40);
    (key == "WIDTH" ? r.h.width : key == "HEIGHT" ? r.h.height : r.h.points) = v;
  } else if (key == "VIEWPOINT") {
    if (f.size() != 8) throw inputError(where.file, where.line, "field 'VIEWPOINT' needs 7 values (tx ty tz qw qx qy qz)");
    for (std::size_t k = 1; k < 8; ++k) parseFinite(f[k], where, "VIEWPOINT");
  } else if (key == "DATA") {
    readData(f, r.h, in, where);
    return false;
  } else {
    throw inputError(where.file, where.line, "unknown header field '" + key + "': not a PCD header");
  }
  return true;
}

/// The header as a whole: every required line there, the point size, and
/// POINTS = WIDTH * HEIGHT.
Header completeHeader(HeaderInProgress& r, const std::string& path) {
  Header& h = r.h;
  if (h.data.empty()) throw InputError(path + ": the PCD header has no DATA line");
  for (const char* required : {"FIELDS", "SIZE", "TYPE", "WIDTH", "HEIGHT"})
    if (!r.seen.count(required)) throw InputError(path + ": the PCD header has no " + required + " line");
  if (r.counts.empty()) r.counts.assign(h.fields, 1);
  for (std::size_t k = 0; k < h.fields; ++k) h.point_size += std::size_t(r.sizes[k] * r.counts[k]);
  constexpr long kMaxPoints = 1L << 40;
  if (h.height > 0 && h.width > kMaxPoints / h.height)
    throw InputError(path + ": WIDTH * HEIGHT (" + std::to_string(h.width) + " * " + std::to_string(h.height) +
                     ") is more points than any file holds");
  if (h.points < 0) h.points = h.width * h.height;
  if (h.points != h.width * h.height)
    throw InputError(path + ": field 'POINTS' (" + std::to_string(h.points) + ") is not WIDTH * HEIGHT (" +
                     std::to_string(h.width * h.height) + ")");
  return h;
}

Header readHeader(std::ifstream& in, const std::string& path) {
  if (in.peek() == std::char_traits<char>::eof()) throw InputError(path + ": the file is empty (0 bytes)");
  HeaderInProgress r;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (number > 64) throw InputError(path + ": no DATA line in the first 64 lines: not a PCD header");
    const auto f = splitFields(line);
    if (f.empty() || f[0].front() == '#') continue;
    if (!readHeaderLine(f, r, in, LineRef{path, number})) break;
  }
  return completeHeader(r, path);
}

}  // namespace

void checkPcdFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  const Header h = readHeader(in, path);
  in.seekg(0, std::ios::end);
  const std::size_t size = static_cast<std::size_t>(in.tellg());
  const std::size_t available = size - h.data_offset;
  if (h.point_size > 0 && std::size_t(h.points) > (std::size_t(1) << 50) / h.point_size)
    throw InputError(path + ": the header declares " + std::to_string(h.points) + " points of " +
                     std::to_string(h.point_size) + " bytes: more data than any file holds");
  const std::size_t expected = std::size_t(h.points) * h.point_size;
  const std::string truncated = path + ": truncated: the header declares " + std::to_string(h.points) + " points";
  if (h.data == "binary" && available < expected)
    throw InputError(truncated + " (" + std::to_string(expected) + " bytes), the file holds " +
                     std::to_string(available));
  // Even for 0 points: PCL reads the two sizes and allocates the
  // uncompressed one as given (a 1.3 GB allocation from 8 forged bytes; found
  // by fuzzing).
  if (h.data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed
    in.seekg(static_cast<std::streamoff>(h.data_offset));
    in.read(reinterpret_cast<char*>(sizes), sizeof sizes);
    if (!in || available < 8 + std::size_t(sizes[0]))
      throw InputError(truncated + "; its compressed data is cut short");
    if (sizes[1] != expected)
      throw InputError(path + ": the compressed data holds " + std::to_string(sizes[1]) + " bytes, the header declares " +
                       std::to_string(expected));
  }
  if (h.data == "ascii") {
    in.clear();
    in.seekg(static_cast<std::streamoff>(h.data_offset));
    std::string line;
    long lines = 0;
    while (lines < h.points && std::getline(in, line))
      if (line.find_first_not_of(" \t\r") != std::string::npos) ++lines;
    if (lines < h.points)
      throw InputError(truncated + ", the file holds " + std::to_string(lines) + " data lines");
  }
}

}  // namespace obsgroup::io
