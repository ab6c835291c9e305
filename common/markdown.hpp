#pragma once
// Text for a Markdown table cell: '|' escaped, line breaks as spaces
// (reports, cohort and study summaries).
#include <string>

namespace stentsim {

inline std::string markdown_cell(const std::string& s) {
  std::string out;
  for (char ch : s) {
    if (ch == '|') out += "\\|";
    else out += ch == '\n' ? ' ' : ch;
  }
  return out;
}

}  // namespace stentsim
