#include "workflows/report/report_writer.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "common/files.hpp"
#include "common/markdown.hpp"

namespace stentsim::workflows::report {
namespace {

// Plain and readable on screen and in print; no fonts or scripts from elsewhere.
constexpr const char* kCss = R"css(
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; color: #222; background: #fff;
       max-width: 1100px; margin: 2em auto; padding: 0 1.5em; line-height: 1.45; font-size: 15px; }
h1 { font-size: 1.7em; border-bottom: 2px solid #345; padding-bottom: 0.2em; }
h2 { font-size: 1.3em; color: #234; margin-top: 1.8em; border-bottom: 1px solid #ccd; }
h3 { font-size: 1.1em; color: #234; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }
th, td { border: 1px solid #bbc; padding: 0.3em 0.6em; text-align: left; vertical-align: top; }
th { background: #e8ecf2; }
tr:nth-child(even) td { background: #f7f8fa; }
td.pass { color: #0a6b1f; font-weight: bold; }
td.fail { color: #b00020; font-weight: bold; }
code { background: #f0f2f5; padding: 0 0.25em; border-radius: 3px; font-size: 0.92em; }
figure { margin: 1.2em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #444; }
)css";

// Markdown and HTML both read `code` spans; HTML gets them as <code>.
std::string inline_html(const std::string& text) {
  std::string out;
  bool code = false;
  std::size_t start = 0;
  while (true) {
    const auto tick = text.find('`', start);
    const std::string part = text.substr(start, tick == std::string::npos ? std::string::npos : tick - start);
    out += code ? "<code>" + html_escape(part) + "</code>" : html_escape(part);
    if (tick == std::string::npos) break;
    code = !code;
    start = tick + 1;
  }
  return out;
}


std::string cell_class(const std::string& s) {
  if (s == "pass" || s.rfind("pass [", 0) == 0 || s == "ok") return " class=\"pass\"";
  if (s.rfind("FAIL", 0) == 0 || s == "failed") return " class=\"fail\"";
  return "";
}

}  // namespace

void Document::heading(int level, std::string text) {
  Block b;
  b.kind = Block::Kind::heading;
  b.level = level;
  b.text = std::move(text);
  blocks_.push_back(std::move(b));
}
void Document::paragraph(std::string text) {
  Block b;
  b.kind = Block::Kind::paragraph;
  b.text = std::move(text);
  blocks_.push_back(std::move(b));
}
void Document::bullets(std::vector<std::string> items) {
  Block b;
  b.kind = Block::Kind::bullets;
  b.items = std::move(items);
  blocks_.push_back(std::move(b));
}
void Document::table(std::vector<std::string> header, std::vector<std::vector<std::string>> rows) {
  Block b;
  b.kind = Block::Kind::table;
  b.items = std::move(header);
  b.rows = std::move(rows);
  blocks_.push_back(std::move(b));
}
void Document::figure(std::string title, std::filesystem::path png, std::string png_link, std::string svg_link, std::string caption) {
  Block b;
  b.kind = Block::Kind::figure;
  b.text = std::move(title);
  b.png = std::move(png);
  b.png_link = std::move(png_link);
  b.svg_link = std::move(svg_link);
  b.caption = std::move(caption);
  blocks_.push_back(std::move(b));
}

std::string Document::markdown() const {
  std::string out;
  for (const auto& b : blocks_) {
    switch (b.kind) {
      case Block::Kind::heading: out += std::string(b.level, '#') + " " + b.text + "\n\n"; break;
      case Block::Kind::paragraph: out += b.text + "\n\n"; break;
      case Block::Kind::bullets:
        for (const auto& i : b.items) out += "- " + i + "\n";
        out += "\n";
        break;
      case Block::Kind::table: {
        std::string head = "|", rule = "|";
        for (const auto& h : b.items) head += " " + markdown_cell(h) + " |", rule += "---|";
        out += head + "\n" + rule + "\n";
        for (const auto& r : b.rows) {
          std::string line = "|";
          for (std::size_t i = 0; i < b.items.size(); ++i) line += " " + markdown_cell(i < r.size() ? r[i] : "") + " |";
          out += line + "\n";
        }
        out += "\n";
        break;
      }
      case Block::Kind::figure:
        out += fmt::format("![{}]({})\n\n*{}* {} (SVG: [{}]({}))\n\n", b.text, b.png_link, b.text, b.caption, b.svg_link, b.svg_link);
        break;
    }
  }
  return out;
}

std::string Document::html(const std::string& title) const {
  std::string out = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  out += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  out += "<title>" + html_escape(title) + "</title>\n<style>" + kCss + "</style>\n</head>\n<body>\n";
  for (const auto& b : blocks_) {
    switch (b.kind) {
      case Block::Kind::heading:
        out += fmt::format("<h{0}>{1}</h{0}>\n", std::clamp(b.level, 1, 6), inline_html(b.text));
        break;
      case Block::Kind::paragraph: out += "<p>" + inline_html(b.text) + "</p>\n"; break;
      case Block::Kind::bullets:
        out += "<ul>\n";
        for (const auto& i : b.items) out += "<li>" + inline_html(i) + "</li>\n";
        out += "</ul>\n";
        break;
      case Block::Kind::table:
        out += "<table>\n<thead><tr>";
        for (const auto& h : b.items) out += "<th>" + inline_html(h) + "</th>";
        out += "</tr></thead>\n<tbody>\n";
        for (const auto& r : b.rows) {
          out += "<tr>";
          for (std::size_t i = 0; i < b.items.size(); ++i) {
            const std::string cell = i < r.size() ? r[i] : "";
            out += "<td" + cell_class(cell) + ">" + inline_html(cell) + "</td>";
          }
          out += "</tr>\n";
        }
        out += "</tbody>\n</table>\n";
        break;
      case Block::Kind::figure:
        out += fmt::format("<figure>\n<img alt=\"{}\" src=\"data:image/png;base64,{}\">\n<figcaption><b>{}</b> {} (SVG: {})</figcaption>\n</figure>\n",
                           html_escape(b.text), base64(files::read_text(b.png)), html_escape(b.text), inline_html(b.caption),
                           inline_html("`" + b.svg_link + "`"));
        break;
    }
  }
  out += "</body>\n</html>\n";
  return out;
}

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace stentsim::workflows::report
