#pragma once

// Result tables, printed as aligned text (stdout) and as Markdown (--markdown), and the format of
// their cells. A report is a list of sections: a title, an intro saying what the columns mean, a
// table and notes.

#include <cstdint>
#include <string>
#include <vector>

namespace geodex::bench {

class Table {
 public:
  // `align`: one 'l' (left) or 'r' (right) per column; columns past its end are right-aligned.
  Table(std::vector<std::string> headers, std::string align);

  // A row; missing cells are empty.
  void AddRow(std::vector<std::string> cells);
  // A blank line in the text form (between meshes); ignored in Markdown.
  void AddBreak() { rows_.push_back({}); }
  bool empty() const { return rows_.empty(); }

  std::string Text() const;
  std::string Markdown() const;

 private:
  std::vector<std::string> headers_;
  std::string align_;
  std::vector<std::vector<std::string>> rows_;
};

struct Section {
  std::string title;
  std::string intro;
  Table table;
  std::vector<std::string> notes;
};

// Prints the sections on stdout as text and returns the same as Markdown.
std::string PrintSections(const std::vector<Section>& sections);

// Cells. Ms: "1234", "123.4", "12.34", "1.234" ("-" if negative or NaN). Ratio: "2.5x" ("-"
// unless finite). Count: "12345". MiBOfKb never writes "-0.0". Sci: "1.2e-15" ("inf" unless
// finite). Percent: "0.123%" ("0" for 0, "-" unless finite).
std::string Ms(double ms);
std::string Ratio(double r);
std::string Count(uint64_t n);
std::string MiBOfBytes(double bytes);
std::string MiBOfKb(int64_t kb);
std::string Sci(double x);
std::string Percent(double fraction);

}  // namespace geodex::bench
