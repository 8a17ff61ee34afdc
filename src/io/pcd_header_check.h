#pragma once
// A strict check of a PCD file's header and data size, run before PCL reads
// the file: PCL 1.13's reader crashes on some malformed headers (garbage
// text, for one) and accepts truncated data.

#include <string>

namespace obsgroup::io {

/// Throws InputError naming the file, the header line and the field when the
/// header is malformed or inconsistent, or when the data is shorter than the
/// header declares.
void checkPcdFile(const std::string& path);

}  // namespace obsgroup::io
