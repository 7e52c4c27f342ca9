// Private helpers shared by the mesh readers: per-format entry points, error formatting, a fast
// line reader and tokenizer over an in-memory buffer, and locale-independent number scanning.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "geodex/mesh_data.h"
#include "geodex/mesh_io.h"

namespace geodex::io_internal {

// One reader per format. `bytes` is already decompressed; `name` prefixes every message.
absl::StatusOr<MeshData> ReadOff(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits);
absl::StatusOr<MeshData> ReadObj(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits);
absl::StatusOr<MeshData> ReadPly(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits);
absl::StatusOr<MeshData> ReadStl(absl::string_view bytes, const std::string& name,
                                 const ReadLimits& limits);

// True when the size matches the triangle count of a binary STL header (84 + 50 * n bytes).
bool IsBinaryStlSize(absl::string_view bytes);

// Face indices are uint32, so no vertex count may exceed this whatever the limits say.
inline uint64_t MaxVertices(const ReadLimits& limits) {
  return limits.max_vertices < uint64_t{UINT32_MAX} ? limits.max_vertices : uint64_t{UINT32_MAX};
}

// "name: line 12: message" (InvalidArgument).
absl::Status LineError(const std::string& name, uint64_t line, absl::string_view message);
// "name: byte 1234: message" (InvalidArgument).
absl::Status ByteError(const std::string& name, uint64_t offset, absl::string_view message);
// A token for a message: quoted, escaped (binary garbage stays on one line) and shortened.
std::string Quote(absl::string_view token);

inline bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

inline const char* SkipBlanks(const char* p, const char* end) {
  while (p != end && IsBlank(*p)) ++p;
  return p;
}

// The token that starts at p (up to the next blank or newline), for error messages.
inline absl::string_view TokenAt(const char* p, const char* end) {
  const char* q = p;
  while (q != end && !IsBlank(*q) && *q != '\n') ++q;
  return absl::string_view(p, static_cast<size_t>(q - p));
}

// Value strtod would give for text that from_chars rejects as out of range: +-inf on overflow,
// +-0 on underflow (NaN/Inf are not the readers' business; the mesh validator reports them).
double OutOfRangeValue(const char* begin, const char* end);

enum class Scan { kOk, kMissing, kBad };

// Scans one number token at *p (after blanks) that must end at a blank, a newline or `end`.
// kOk advances *p past it; kMissing/kBad leave *p at the token start (for TokenAt).
inline Scan ScanDouble(const char** p, const char* end, double* out) {
  const char* s = SkipBlanks(*p, end);
  *p = s;
  if (s == end || *s == '\n') return Scan::kMissing;
  const char* q = s;
  if (*q == '+') {  // from_chars does not take a leading '+'
    ++q;
    if (q == end || *q == '-') return Scan::kBad;
  }
  auto [ptr, ec] = std::from_chars(q, end, *out);
  if (ec == std::errc::result_out_of_range) {
    *out = OutOfRangeValue(q, ptr);
  } else if (ec != std::errc()) {
    return Scan::kBad;
  }
  if (ptr != end && !IsBlank(*ptr) && *ptr != '\n') return Scan::kBad;
  *p = ptr;
  return Scan::kOk;
}

inline Scan ScanInt(const char** p, const char* end, int64_t* out) {
  const char* s = SkipBlanks(*p, end);
  *p = s;
  if (s == end || *s == '\n') return Scan::kMissing;
  const char* q = s;
  if (*q == '+') {
    ++q;
    if (q == end || *q == '-') return Scan::kBad;
  }
  auto [ptr, ec] = std::from_chars(q, end, *out);
  if (ec != std::errc()) return Scan::kBad;
  if (ptr != end && !IsBlank(*ptr) && *ptr != '\n') return Scan::kBad;
  *p = ptr;
  return Scan::kOk;
}

// Whole-token parsers (the token has no surrounding blanks).
inline bool ParseDouble(absl::string_view token, double* out) {
  const char* p = token.data();
  return !token.empty() && ScanDouble(&p, p + token.size(), out) == Scan::kOk &&
         p == token.data() + token.size();
}
inline bool ParseInt(absl::string_view token, int64_t* out) {
  const char* p = token.data();
  return !token.empty() && ScanInt(&p, p + token.size(), out) == Scan::kOk &&
         p == token.data() + token.size();
}

// Splits a buffer into lines ('\n'; a trailing '\r' is dropped), optionally cutting '#' comments.
class LineReader {
 public:
  LineReader(absl::string_view text, bool hash_comments)
      : p_(text.data()),
        end_(text.data() + text.size()),
        begin_(text.data()),
        hash_comments_(hash_comments) {}

  // The next line; false at the end of the buffer.
  bool Next(absl::string_view* line) {
    if (p_ == end_) return false;
    const char* nl = static_cast<const char*>(std::memchr(p_, '\n', end_ - p_));
    const char* line_end = nl ? nl : end_;
    const char* content_end = line_end;
    if (hash_comments_) {
      const char* hash = static_cast<const char*>(std::memchr(p_, '#', line_end - p_));
      if (hash) content_end = hash;
    }
    if (content_end != p_ && content_end[-1] == '\r') --content_end;
    *line = absl::string_view(p_, static_cast<size_t>(content_end - p_));
    p_ = nl ? nl + 1 : end_;
    ++line_number_;
    return true;
  }

  // The next line that is not blank, with its leading blanks removed.
  bool NextNonBlank(absl::string_view* line) {
    while (Next(line)) {
      const char* s = SkipBlanks(line->data(), line->data() + line->size());
      if (s != line->data() + line->size()) {
        line->remove_prefix(static_cast<size_t>(s - line->data()));
        return true;
      }
    }
    return false;
  }

  uint64_t line_number() const { return line_number_; }               // of the last line returned
  size_t offset() const { return static_cast<size_t>(p_ - begin_); }  // just past that line
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }

 private:
  const char* p_;
  const char* end_;
  const char* begin_;
  bool hash_comments_;
  uint64_t line_number_ = 0;
};

// Whitespace-separated tokens across lines, keeping the line number (ascii PLY and STL bodies).
class TokenReader {
 public:
  TokenReader(absl::string_view text, uint64_t first_line)
      : p_(text.data()), end_(text.data() + text.size()), line_(first_line) {}

  // The next token; false at the end of the buffer. line() is then the token's line.
  bool Next(absl::string_view* token) {
    SkipSpace();
    if (p_ == end_) return false;
    const char* s = p_;
    while (p_ != end_ && !IsBlank(*p_) && *p_ != '\n') ++p_;
    *token = absl::string_view(s, static_cast<size_t>(p_ - s));
    return true;
  }

  // Drops everything up to and including the next newline (e.g. an STL solid name).
  void SkipRestOfLine() {
    const char* nl = static_cast<const char*>(std::memchr(p_, '\n', end_ - p_));
    if (nl) {
      p_ = nl + 1;
      ++line_;
    } else {
      p_ = end_;
    }
  }

  bool AtEnd() {
    SkipSpace();
    return p_ == end_;
  }
  uint64_t line() const { return line_; }
  size_t remaining() const { return static_cast<size_t>(end_ - p_); }

 private:
  void SkipSpace() {
    while (p_ != end_ && (IsBlank(*p_) || *p_ == '\n')) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
  }

  const char* p_;
  const char* end_;
  uint64_t line_;
};

}  // namespace geodex::io_internal
