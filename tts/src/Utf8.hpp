// UTF-8 text as code points and back, and the lower case of the alphabets the script languages
// use: what reading a script's words needs (TextScript, Reductions) without a Unicode library.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace lipsyncd::utf8 {

// Code points of UTF-8 text (invalid bytes count as one code point each).
std::vector<char32_t> codePoints(std::string_view s);
void append(std::string& out, char32_t c);
// The lower-case twin of a capital in Latin, Latin-1, Greek and Cyrillic; any other code point
// is its own.
char32_t lowerCase(char32_t c);

}  // namespace lipsyncd::utf8
