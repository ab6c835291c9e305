#pragma once
// The report as a list of blocks (headings, paragraphs, lists, tables,
// figures), rendered once as Markdown and once as HTML, so that the two files
// cannot drift apart. Text may hold `code` spans in backticks, the only inline
// markup. The HTML is one self-contained file: inline CSS, the figures' PNGs
// as base64 data: URIs, every text escaped, nothing loaded from elsewhere.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace stentsim::workflows::report {

class Document {
 public:
  void heading(int level, std::string text);
  void paragraph(std::string text);
  void bullets(std::vector<std::string> items);
  /// Cells reading "pass"/"ok" or "FAIL"/"failed" are coloured in the HTML.
  void table(std::vector<std::string> header, std::vector<std::vector<std::string>> rows);
  /// `png` is read when the HTML is rendered; the links are what Markdown
  /// shows (relative to the report's folder).
  void figure(std::string title, std::filesystem::path png, std::string png_link, std::string svg_link, std::string caption);

  std::string markdown() const;
  /// InputError naming the PNG when a figure's file cannot be read.
  std::string html(const std::string& title) const;

 private:
  struct Block {
    enum class Kind { heading, paragraph, bullets, table, figure } kind = Kind::paragraph;
    int level = 0;
    std::string text;  // heading, paragraph, figure title
    std::vector<std::string> items;  // bullets, table header
    std::vector<std::vector<std::string>> rows;
    std::filesystem::path png;
    std::string png_link, svg_link, caption;
  };
  std::vector<Block> blocks_;
};

std::string base64(std::string_view bytes);
std::string html_escape(std::string_view text);

}  // namespace stentsim::workflows::report
