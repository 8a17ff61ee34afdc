#pragma once
// The bytes of an input file or of standard input ("-"), and gzip: logs and
// pose files are read compressed or not, whatever their name says.

#include <string>
#include <string_view>

namespace obsgroup::io {

/// The name of `path` in messages: "-" (standard input) is "<stdin>".
std::string inputName(const std::string& path);

/// The bytes of the file at `path`, or of standard input for "-", as they
/// are (not inflated). Throws InputError when it cannot be read; `what`
/// names it ("file", "poses file").
std::string readInputBytes(const std::string& path, const std::string& what = "file");

/// True when `bytes` start with gzip's magic bytes 1f 8b.
bool isGzip(std::string_view bytes);

/// The inflated content of gzip data (one or more members). Throws
/// InputError naming `name` when the data are corrupt, or cut short unless
/// `cut_short` is given: then what was inflated is returned and
/// *cut_short says so.
std::string gunzip(std::string_view bytes, const std::string& name, std::string* cut_short = nullptr);

/// `content` without a leading UTF-8 byte-order mark (EF BB BF).
std::string_view withoutByteOrderMark(std::string_view content);

}  // namespace obsgroup::io
