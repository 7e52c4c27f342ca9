// Entry points of the mesh readers: load the file, gunzip when it carries the gzip magic, pick the
// format from the extension or by sniffing the content, and hand the bytes to the format's reader.
#include "geodex/mesh_io.h"

#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "geodex/limits.h"
#include "io/io_util.h"

namespace geodex {
namespace io_internal {

absl::Status LineError(const std::string& name, uint64_t line, absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat(name, ": line ", line, ": ", message));
}

absl::Status ByteError(const std::string& name, uint64_t offset, absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat(name, ": byte ", offset, ": ", message));
}

std::string Quote(absl::string_view token) {
  constexpr size_t kMaxShown = 32;
  const bool cut = token.size() > kMaxShown;
  return absl::StrCat("'", absl::CHexEscape(token.substr(0, kMaxShown)), cut ? "...'" : "'");
}

double OutOfRangeValue(const char* begin, const char* end) {
  // Only called for decimal text beyond the double range, so the sign of the decimal exponent of
  // the leading significant digit tells overflow from underflow.
  const bool negative = begin != end && *begin == '-';
  const char* p = begin + (negative ? 1 : 0);
  bool seen_point = false, seen_digit = false;
  int64_t int_digits = 0, leading_fraction_zeros = 0;
  for (; p != end && (absl::ascii_isdigit(*p) || *p == '.'); ++p) {
    if (*p == '.') {
      seen_point = true;
    } else if (!seen_point) {
      if (seen_digit || *p != '0') {
        seen_digit = true;
        ++int_digits;
      }
    } else if (!seen_digit) {
      if (*p == '0') {
        ++leading_fraction_zeros;
      } else {
        seen_digit = true;
      }
    }
  }
  int64_t magnitude = int_digits > 0 ? int_digits - 1 : -(leading_fraction_zeros + 1);
  if (p != end && (*p == 'e' || *p == 'E')) {
    ++p;
    const bool exp_negative = p != end && *p == '-';
    if (p != end && (*p == '-' || *p == '+')) ++p;
    int64_t exponent = 0;
    for (; p != end && absl::ascii_isdigit(*p); ++p) {
      exponent = std::min<int64_t>(exponent * 10 + (*p - '0'), int64_t{1} << 40);
    }
    magnitude += exp_negative ? -exponent : exponent;
  }
  const double value = magnitude > 0 ? HUGE_VAL : 0.0;
  return negative ? -value : value;
}

bool IsBinaryStlSize(absl::string_view bytes) {
  if (bytes.size() < 84) return false;
  uint32_t count = 0;
  for (int i = 3; i >= 0; --i) count = (count << 8) | static_cast<uint8_t>(bytes[80 + i]);
  return 84 + 50 * uint64_t{count} == bytes.size();
}

}  // namespace io_internal

namespace {

using io_internal::Quote;

bool IsGzip(absl::string_view bytes) {
  return bytes.size() >= 2 && static_cast<uint8_t>(bytes[0]) == 0x1f &&
         static_cast<uint8_t>(bytes[1]) == 0x8b;
}

// Inflates every gzip member (concatenated members are valid gzip), never beyond `max_bytes`.
absl::StatusOr<std::string> Gunzip(absl::string_view in, const std::string& name,
                                   uint64_t max_bytes) {
  z_stream zs;
  std::memset(&zs, 0, sizeof(zs));
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) {
    return absl::InternalError(absl::StrCat(name, ": cannot initialise zlib"));
  }
  // The trailer's size (mod 2^32) is only a hint: trusted when the ratio is plausible.
  uint64_t initial = std::max<uint64_t>(uint64_t{4} * in.size(), 1 << 16);
  if (in.size() >= 18) {
    uint32_t isize = 0;
    for (int i = 3; i >= 0; --i) isize = (isize << 8) | static_cast<uint8_t>(in[in.size() - 4 + i]);
    if (isize > 0 && isize <= uint64_t{64} * in.size()) initial = uint64_t{isize} + 1;
  }
  std::string out;
  out.resize(static_cast<size_t>(std::min<uint64_t>(initial, max_bytes + 1)));
  uint64_t produced = 0;
  size_t consumed = 0;
  absl::Status status;
  while (true) {
    if (produced == out.size()) {
      if (produced > max_bytes) {
        status = LimitExceededError(
            Limit::kInputBytes,
            absl::StrCat(name, ": decompressed data exceeds the limit of ", max_bytes, " bytes"));
        break;
      }
      out.resize(static_cast<size_t>(std::min<uint64_t>(2 * out.size(), max_bytes + 1)));
    }
    // zlib counts in uInt; feed at most 1 GiB per call.
    const size_t in_chunk = std::min<size_t>(in.size() - consumed, size_t{1} << 30);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + consumed));
    zs.avail_in = static_cast<uInt>(in_chunk);
    const size_t out_chunk = std::min<size_t>(out.size() - produced, size_t{1} << 30);
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
    zs.avail_out = static_cast<uInt>(out_chunk);
    const int rc = inflate(&zs, Z_NO_FLUSH);
    consumed += in_chunk - zs.avail_in;
    produced += out_chunk - zs.avail_out;
    if (rc == Z_STREAM_END) {
      const absl::string_view rest = in.substr(consumed);
      if (rest.empty()) break;
      if (IsGzip(rest)) {
        inflateReset(&zs);
        continue;
      }
      if (rest.find_first_not_of('\0') == absl::string_view::npos) break;  // tape padding
      status = absl::InvalidArgumentError(
          absl::StrCat(name, ": byte ", consumed, ": unexpected data after the gzip stream"));
      break;
    }
    if (rc == Z_OK) continue;
    if (rc == Z_BUF_ERROR && consumed == in.size() && zs.avail_out > 0) {
      status = absl::InvalidArgumentError(absl::StrCat(
          name, ": byte ", consumed, ": truncated gzip data (the compressed stream ends early)"));
      break;
    }
    if (rc == Z_BUF_ERROR) continue;  // output full: grown at the top of the loop
    status = absl::InvalidArgumentError(absl::StrCat(
        name, ": byte ", consumed, ": corrupt gzip data (", zs.msg ? zs.msg : "zlib error", ")"));
    break;
  }
  inflateEnd(&zs);
  if (!status.ok()) return status;
  out.resize(static_cast<size_t>(produced));
  return out;
}

// The extension after dropping ".gz", lowercased (".off"), or empty.
std::string Extension(const std::string& name) {
  std::string lower = absl::AsciiStrToLower(name);
  if (absl::EndsWith(lower, ".gz")) lower.resize(lower.size() - 3);
  const size_t slash = lower.find_last_of("/\\");
  const size_t dot = lower.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower.substr(dot);
}

MeshFormat FormatFromExtension(const std::string& name) {
  const std::string ext = Extension(name);
  if (ext == ".off") return MeshFormat::kOff;
  if (ext == ".obj") return MeshFormat::kObj;
  if (ext == ".ply") return MeshFormat::kPly;
  if (ext == ".stl") return MeshFormat::kStl;
  return MeshFormat::kAuto;
}

// Guesses the format from the content when the name does not tell.
MeshFormat SniffFormat(absl::string_view bytes) {
  io_internal::LineReader lines(bytes, /*hash_comments=*/true);
  absl::string_view line;
  if (lines.NextNonBlank(&line)) {
    const absl::string_view first = io_internal::TokenAt(line.data(), line.data() + line.size());
    if (absl::EndsWith(first, "OFF") && first.size() <= 7) return MeshFormat::kOff;
  }
  if (absl::StartsWith(bytes, "ply\n") || absl::StartsWith(bytes, "ply\r\n")) {
    return MeshFormat::kPly;
  }
  io_internal::LineReader stl_lines(bytes, /*hash_comments=*/false);
  if (stl_lines.NextNonBlank(&line) && absl::StartsWith(line, "solid") &&
      !io_internal::IsBinaryStlSize(bytes) && stl_lines.NextNonBlank(&line) &&
      (absl::StartsWith(line, "facet") || absl::StartsWith(line, "endsolid"))) {
    return MeshFormat::kStl;
  }
  if (io_internal::IsBinaryStlSize(bytes)) return MeshFormat::kStl;
  io_internal::LineReader obj_lines(bytes, /*hash_comments=*/true);
  while (obj_lines.NextNonBlank(&line)) {
    if (line.size() >= 2 && line[0] == 'v' && io_internal::IsBlank(line[1])) {
      return MeshFormat::kObj;
    }
  }
  return MeshFormat::kAuto;
}

}  // namespace

absl::StatusOr<MeshData> ReadMeshFromBuffer(absl::string_view bytes, MeshFormat format,
                                            const std::string& name, const ReadLimits& limits) {
  std::string inflated;
  if (IsGzip(bytes)) {
    absl::StatusOr<std::string> out = Gunzip(bytes, name, limits.max_decompressed_bytes);
    if (!out.ok()) return out.status();
    inflated = std::move(*out);
    bytes = absl::string_view(inflated);
  }
  if (format == MeshFormat::kAuto) format = FormatFromExtension(name);
  if (format == MeshFormat::kAuto) format = SniffFormat(bytes);
  switch (format) {
    case MeshFormat::kOff:
      return io_internal::ReadOff(bytes, name, limits);
    case MeshFormat::kObj:
      return io_internal::ReadObj(bytes, name, limits);
    case MeshFormat::kPly:
      return io_internal::ReadPly(bytes, name, limits);
    case MeshFormat::kStl:
      return io_internal::ReadStl(bytes, name, limits);
    case MeshFormat::kAuto:
      break;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      name, ": unrecognised mesh format (expected OFF, OBJ, PLY or STL), starting with ",
      Quote(bytes.substr(0, 16))));
}

absl::StatusOr<MeshData> ReadMeshFile(const std::string& path, const ReadLimits& limits) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    const int err = errno;
    const std::string message = absl::StrCat(path, ": cannot open: ", std::strerror(err));
    return err == ENOENT ? absl::NotFoundError(message) : absl::PermissionDeniedError(message);
  }
  if (struct stat st; fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
    std::fclose(f);  // fopen opens a directory; reading it would fail with a vaguer reason
    return absl::InvalidArgumentError(absl::StrCat(path, ": is a directory, not a mesh file"));
  }
  std::string bytes;
  absl::Status status;
  if (std::fseek(f, 0, SEEK_END) == 0) {
    const long size = std::ftell(f);
    if (size >= 0 && static_cast<uint64_t>(size) > limits.max_decompressed_bytes) {
      status = LimitExceededError(Limit::kInputBytes,
                                  absl::StrCat(path, ": file size ", size, " exceeds the limit of ",
                                               limits.max_decompressed_bytes, " bytes"));
    } else if (size > 0) {
      bytes.reserve(static_cast<size_t>(size));
    }
    std::rewind(f);
  }
  // Read in chunks rather than trusting ftell (pipes and /proc files report 0).
  char buffer[1 << 16];
  while (status.ok()) {
    const size_t n = std::fread(buffer, 1, sizeof(buffer), f);
    bytes.append(buffer, n);
    if (bytes.size() > limits.max_decompressed_bytes) {
      status = LimitExceededError(Limit::kInputBytes,
                                  absl::StrCat(path, ": file exceeds the limit of ",
                                               limits.max_decompressed_bytes, " bytes"));
    }
    if (n < sizeof(buffer)) {
      if (std::ferror(f)) {
        status = absl::DataLossError(absl::StrCat(path, ": read error: ", std::strerror(errno)));
      }
      break;
    }
  }
  std::fclose(f);
  if (!status.ok()) return status;
  return ReadMeshFromBuffer(bytes, MeshFormat::kAuto, path, limits);
}

}  // namespace geodex
