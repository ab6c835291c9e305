#pragma once
// File helpers: write-to-temporary-then-rename (DESIGN.md §7) and content hashes.
#include <filesystem>
#include <string>

namespace stentsim::files {

/// Writes `content` to `target` atomically: a temporary file in the same
/// folder, flushed, then renamed over the target. The old file survives any failure.
void write_atomic(const std::filesystem::path& target, const std::string& content);

/// A temporary name beside `target` (same folder, so rename is atomic):
/// "<dir>/.<name>.tmp-<pid>".
std::filesystem::path temporary_name_for(const std::filesystem::path& target);

/// Renames `from` onto `to`, replacing it (files or folders).
void replace(const std::filesystem::path& from, const std::filesystem::path& to);

/// InputError unless `file` is a regular file (resolving symbolic links): "<file>:
/// file not found", or "not a regular file (a folder, device or pipe)" — a FIFO or a
/// device would block a reader or feed it without end. `what` names the file in the
/// remedy ("give the <what> itself").
void require_regular_file(const std::filesystem::path& file, const std::string& what = "file");

/// Reads a whole regular file (require_regular_file); throws InputError naming it
/// when it cannot be read.
std::string read_text(const std::filesystem::path& file);

/// 128-bit xxHash (XXH3) of a file's content as 32 hex digits. For a folder,
/// the hash of its files' relative names and contents in sorted order.
std::string content_hash(const std::filesystem::path& path);

/// 128-bit xxHash (XXH3) of a string, 32 hex digits.
std::string text_hash(const std::string& text);

/// The last `n` non-empty lines of a text file (a child's log) joined by " | ",
/// for a one-line failure message; empty when the file is missing, unreadable
/// or blank.
std::string log_tail(const std::filesystem::path& file, std::size_t n);

}  // namespace stentsim::files
