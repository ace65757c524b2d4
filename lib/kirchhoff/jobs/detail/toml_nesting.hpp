// A guard in front of toml11: how deeply TOML text nests, found by a linear scan.
#pragma once

#include <cstddef>
#include <string>

namespace kirchhoff {

// The first line on which arrays and inline tables nest deeper than `limit` in TOML text, 0 when
// none does. Each level counts, and so does each dot of the dotted keys leading to one (a.b.c =
// [..] counts 3; [a.b.c] headers count the same way): toml11 recurses once per
// level while parsing and again while destroying the tree, and a few thousand levels overflow
// the stack. Only strings and comments have to be told apart, so that brackets inside them are
// not counted; for malformed text the scan may count too much, never too little before the
// point where toml11 would stop with a syntax error (a basic string ends at its line's end, as
// toml11 reads it).
int toml_line_beyond_nesting(const std::string& text, int limit);

// The offset of the first byte that does not start a valid UTF-8 sequence (RFC 3629: no
// overlong forms, no surrogates, at most U+10FFFF), text.size() when there is none. TOML text is
// UTF-8; toml11 3.7 reports invalid UTF-8 inside a literal string ('..' or '''..''') by rewinding
// an iterator of the whole text over a copy of the string, reading past the copy's end (heap
// overflow, found by fuzz/case_file_fuzzer), so load_case refuses such text before toml11 sees it.
std::size_t toml_invalid_utf8_at(const std::string& text);

}  // namespace kirchhoff
