#include <obsgroup/io/input_file.h>

#include <obsgroup/io/errors.h>

#include <zlib.h>
#ifdef OBSGROUP_HAVE_LIBDEFLATE
#include <libdeflate.h>
#endif

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>

namespace obsgroup::io {

std::string inputName(const std::string& path) { return path == "-" ? "<stdin>" : path; }

namespace {

std::string readStream(std::FILE* in) {
  std::string content;
  std::size_t size = 0;
  for (;;) {
    content.resize(std::max<std::size_t>(size + (std::size_t(1) << 20), content.size() * 2));
    const std::size_t got = std::fread(content.data() + size, 1, content.size() - size, in);
    size += got;
    if (got == 0) break;
  }
  content.resize(size);
  return content;
}

}  // namespace

std::string readInputBytes(const std::string& path, const std::string& what) {
  if (path == "-") {
    std::string content = readStream(stdin);
    if (std::ferror(stdin)) throw InputError("<stdin>: cannot read standard input");
    return content;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the " + what);
  const std::streamoff size = in.seekg(0, std::ios::end) ? std::streamoff(in.tellg()) : -1;
  if (size < 0) {  // not seekable (a named pipe): stream it
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file) throw InputError(path + ": cannot open the " + what);
    std::string content = readStream(file);
    std::fclose(file);
    return content;
  }
  std::string content(static_cast<std::size_t>(size), '\0');  // a regular file: one read
  in.seekg(0);
  in.read(content.data(), size);
  content.resize(static_cast<std::size_t>(in.gcount()));
  return content;
}

bool isGzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

std::string_view withoutByteOrderMark(std::string_view content) {
  if (content.substr(0, 3) == "\xEF\xBB\xBF") content.remove_prefix(3);
  return content;
}

namespace {

/// The size the gzip data say they inflate to: the last member's trailer
/// holds it modulo 2^32. Deflate cannot exceed ~1032:1, so a forged trailer
/// cannot ask for more than that.
std::size_t sizeHint(std::string_view bytes) {
  if (bytes.size() < 18) return 1 << 16;
  const auto* tail = reinterpret_cast<const unsigned char*>(bytes.data() + bytes.size() - 4);
  const std::size_t isize = std::size_t(tail[0]) | std::size_t(tail[1]) << 8 | std::size_t(tail[2]) << 16 |
                            std::size_t(tail[3]) << 24;
  return std::max<std::size_t>(1 << 16, std::min(isize, bytes.size() * 1100 + 64));
}

/// Inflates gzip members with zlib, streaming, appending to out[0, produced)
/// (grown as needed); names any problem.
void zlibInflate(std::string_view bytes, const std::string& name, std::string& out, std::size_t& produced,
                 std::string* cut_short) {
  z_stream stream{};
  if (inflateInit2(&stream, 15 + 16) != Z_OK) throw InputError(name + ": cannot start inflating the gzip data");
  const auto* next = reinterpret_cast<const unsigned char*>(bytes.data());
  std::size_t left = bytes.size();
  const auto fail = [&](const std::string& why) {
    inflateEnd(&stream);
    return InputError(name + ": " + why);
  };
  for (;;) {
    if (produced == out.size()) out.resize(std::max<std::size_t>(out.size() * 2, 1 << 16));
    constexpr std::size_t kChunk = std::numeric_limits<uInt>::max();
    stream.next_in = const_cast<unsigned char*>(next);
    stream.avail_in = static_cast<uInt>(std::min(left, kChunk));
    stream.next_out = reinterpret_cast<unsigned char*>(out.data() + produced);
    stream.avail_out = static_cast<uInt>(std::min(out.size() - produced, kChunk));
    const uInt in_before = stream.avail_in, out_before = stream.avail_out;
    const int status = inflate(&stream, Z_NO_FLUSH);
    next += in_before - stream.avail_in;
    left -= in_before - stream.avail_in;
    produced += out_before - stream.avail_out;
    if (status == Z_STREAM_END) {
      if (!isGzip(std::string_view(reinterpret_cast<const char*>(next), left))) break;  // trailing padding: ignored
      inflateReset(&stream);  // another member (gzip files may be concatenated)
      continue;
    }
    if (status == Z_DATA_ERROR || status == Z_NEED_DICT)
      throw fail(std::string("corrupt gzip data (") + (stream.msg ? stream.msg : "bad data") + ")");
    if (status == Z_MEM_ERROR) throw fail("out of memory inflating the gzip data");
    if (status == Z_BUF_ERROR && left == 0) {
      if (!cut_short) throw fail("the gzip data are cut short (a file not completely written or copied?)");
      *cut_short = name + ": the gzip data are cut short";
      break;  // keep what was inflated
    }
    if (status != Z_OK && status != Z_BUF_ERROR) throw fail("cannot inflate the gzip data");
  }
  inflateEnd(&stream);
}

}  // namespace

std::string gunzip(std::string_view bytes, const std::string& name, std::string* cut_short) {
  std::string out(sizeHint(bytes), '\0');  // one buffer, of the final size when the trailer says it
  std::size_t produced = 0;
#ifdef OBSGROUP_HAVE_LIBDEFLATE
  // libdeflate inflates a whole member about twice as fast as zlib,
  // but only into a buffer large enough; whatever it cannot do (a member
  // larger than the hint, bad or cut data, for zlib's precise message) is
  // left to zlib from that member on.
  if (libdeflate_decompressor* decompressor = libdeflate_alloc_decompressor()) {
    while (isGzip(bytes)) {
      std::size_t used = 0, got = 0;
      const libdeflate_result result = libdeflate_gzip_decompress_ex(
          decompressor, bytes.data(), bytes.size(), out.data() + produced, out.size() - produced, &used, &got);
      if (result != LIBDEFLATE_SUCCESS) break;
      produced += got;
      bytes.remove_prefix(used);
    }
    libdeflate_free_decompressor(decompressor);
    if (!isGzip(bytes)) {  // all inflated (what follows the last member is ignored, as gzip does)
      out.resize(produced);
      return out;
    }
  }
#endif
  zlibInflate(bytes, name, out, produced, cut_short);
  out.resize(produced);
  return out;
}

}  // namespace obsgroup::io
