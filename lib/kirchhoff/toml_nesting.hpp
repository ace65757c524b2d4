// A guard in front of toml11: how deeply TOML text nests, found by a linear scan.
#pragma once

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

}  // namespace kirchhoff
