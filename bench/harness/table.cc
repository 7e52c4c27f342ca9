#include "harness/table.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace geodex::bench {
namespace {

constexpr double kMiB = 1024.0 * 1024.0;

std::string Notes(const std::vector<std::string>& notes) {
  std::string out;
  for (const std::string& n : notes) out += "- " + n + "\n";
  return out;
}

}  // namespace

Table::Table(std::vector<std::string> headers, std::string align)
    : headers_(std::move(headers)), align_(std::move(align)) {
  align_.resize(headers_.size(), 'r');
}

void Table::AddRow(std::vector<std::string> cells) {
  cells.resize(headers_.size());
  rows_.push_back(std::move(cells));
}

std::string Table::Text() const {
  std::vector<size_t> width(headers_.size());
  for (size_t c = 0; c < headers_.size(); ++c) width[c] = headers_[c].size();
  for (const auto& row : rows_) {
    for (size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  }
  auto line = [&](const std::vector<std::string>& cells) {
    std::string out;
    for (size_t c = 0; c < cells.size(); ++c) {
      const std::string pad(width[c] - cells[c].size(), ' ');
      if (c > 0) out += "  ";
      out += align_[c] == 'l' ? cells[c] + pad : pad + cells[c];
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out + "\n";
  };
  std::string out = line(headers_);
  size_t total = 0;
  for (size_t w : width) total += w + 2;
  out += std::string(total - 2, '-') + "\n";
  for (const auto& row : rows_) out += row.empty() ? "\n" : line(row);
  return out;
}

std::string Table::Markdown() const {
  std::string out = "| " + absl::StrJoin(headers_, " | ") + " |\n|";
  for (size_t c = 0; c < headers_.size(); ++c) {
    out += align_[c] == 'l' ? "---|" : "---:|";
  }
  out += "\n";
  for (const auto& row : rows_) {
    if (!row.empty()) out += "| " + absl::StrJoin(row, " | ") + " |\n";
  }
  return out;
}

std::string PrintSections(const std::vector<Section>& sections) {
  std::string markdown;
  for (const Section& s : sections) {
    std::printf("\n== %s ==\n%s\n\n%s", s.title.c_str(), s.intro.c_str(), s.table.Text().c_str());
    if (!s.notes.empty()) std::printf("\n%s", Notes(s.notes).c_str());
    absl::StrAppend(&markdown, "\n### ", s.title, "\n\n", s.intro, "\n\n", s.table.Markdown());
    if (!s.notes.empty()) absl::StrAppend(&markdown, "\n", Notes(s.notes));
  }
  return markdown;
}

std::string Ms(double ms) {
  if (!(ms >= 0)) return "-";
  if (ms >= 1000) return absl::StrFormat("%.0f", ms);
  if (ms >= 100) return absl::StrFormat("%.1f", ms);
  if (ms >= 10) return absl::StrFormat("%.2f", ms);
  return absl::StrFormat("%.3f", ms);
}

std::string Ratio(double r) { return std::isfinite(r) ? absl::StrFormat("%.1fx", r) : "-"; }

std::string Count(uint64_t n) { return absl::StrCat(n); }

std::string MiBOfBytes(double bytes) { return absl::StrFormat("%.1f", bytes / kMiB); }

std::string MiBOfKb(int64_t kb) {
  const double mib = kb / 1024.0;
  return absl::StrFormat("%.1f", std::abs(mib) < 0.05 ? 0.0 : mib);  // no "-0.0"
}

std::string Sci(double x) { return std::isfinite(x) ? absl::StrFormat("%.1e", x) : "inf"; }

std::string Percent(double fraction) {
  if (!std::isfinite(fraction)) return "-";
  if (fraction == 0) return "0";
  return absl::StrFormat("%.3g%%", 100 * fraction);
}

}  // namespace geodex::bench
