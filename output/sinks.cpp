#include "output/sinks.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <unicode/uchar.h>
#include <unicode/uspoof.h>
#include <unicode/utf8.h>
#include <unicode/utypes.h>

#include "output/joined.hpp"
#include "output/names.hpp"

namespace quadgen::output {
namespace {

std::string hex_byte(unsigned char c, const char* prefix) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%s%02X", prefix, static_cast<unsigned>(c));
  return buf;
}

bool control(unsigned char c) { return c < 0x20 || c == 0x7f; }

// Length of the valid UTF-8 sequence starting at s[i] (1 for ASCII), or 0 if it is not one.
size_t utf8_length(const std::string& s, size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  if (c < 0x80) return 1;
  size_t n = 0;
  unsigned min = 0;
  if ((c & 0xE0) == 0xC0) n = 2, min = 0x80;
  else if ((c & 0xF0) == 0xE0) n = 3, min = 0x800;
  else if ((c & 0xF8) == 0xF0) n = 4, min = 0x10000;
  else return 0;
  if (i + n > s.size()) return 0;
  unsigned cp = c & (0x7F >> n);
  for (size_t k = 1; k < n; ++k) {
    const auto b = static_cast<unsigned char>(s[i + k]);
    if ((b & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

// Calls emit(piece) for each character: ASCII bytes one by one, valid multi-byte UTF-8
// sequences whole, and "?" for each byte of invalid UTF-8.
template <typename Emit>
void for_each_char(const std::string& s, Emit emit) {
  for (size_t i = 0; i < s.size();) {
    const size_t n = utf8_length(s, i);
    if (n == 0) {
      emit(std::string("?"));
      ++i;
    } else {
      emit(s.substr(i, n));
      i += n;
    }
  }
}

}  // namespace

// A character a terminal acts on instead of showing, beyond the C0 controls: the C1 controls
// U+0080..U+009F (a UTF-8 encoded U+009B is CSI to terminals that honour C1 in UTF-8), and
// the bidirectional overrides and isolates (U+202A..U+202E, U+2066..U+2069), which reorder
// what a reader sees ("Trojan Source"), with the implicit marks that steer them (LRM and RLM,
// U+200E and U+200F; the Arabic letter mark U+061C), and the line and paragraph separators
// (U+2028, U+2029), which editors, some terminals and JavaScript take as line breaks.
bool invisible_control(const std::string& c) {
  const auto b = [&](size_t i) { return static_cast<unsigned char>(c[i]); };
  if (c.size() == 2) return (b(0) == 0xC2 && b(1) >= 0x80 && b(1) <= 0x9F) || (b(0) == 0xD8 && b(1) == 0x9C);
  if (c.size() == 3 && b(0) == 0xE2 && b(1) == 0x80)
    return (b(2) >= 0xA8 && b(2) <= 0xAE) || b(2) == 0x8E || b(2) == 0x8F;
  if (c.size() == 3 && b(0) == 0xE2 && b(1) == 0x81) return b(2) >= 0xA6 && b(2) <= 0xA9;
  return false;
}

std::string printable(const std::string& s) {
  std::string out;
  for_each_char(s, [&](const std::string& c) {
    if (c.size() == 1 && control(static_cast<unsigned char>(c[0]))) out += hex_byte(static_cast<unsigned char>(c[0]), "\\x");
    else if (invisible_control(c))
      for (unsigned char byte : c) out += hex_byte(byte, "\\x");
    else out += c;
  });
  return out;
}

namespace {
constexpr size_t kErrorHead = 1000, kErrorTail = 600;
bool utf8_continuation(const std::string& s, size_t i) {
  return i < s.size() && (static_cast<unsigned char>(s[i]) & 0xC0) == 0x80;
}
// `cut` moved back to the start of the character it falls in.
size_t character_start(const std::string& s, size_t cut) {
  while (cut > 0 && utf8_continuation(s, cut)) --cut;
  return cut;
}
}  // namespace

std::string printable_error(const std::string& message) {
  if (message.size() <= kErrorHead + kErrorTail + 100) return printable(message);
  const size_t head = character_start(message, kErrorHead);  // whole characters on both sides
  size_t tail = message.size() - kErrorTail;
  while (utf8_continuation(message, tail)) ++tail;
  return printable(message.substr(0, head)) + " [... " + std::to_string(tail - head) + " bytes left out ...] " +
         printable(message.substr(tail));
}

std::string printable_head(const std::string& s, size_t max_bytes) {
  if (s.size() <= max_bytes) return printable(s);
  return printable(s.substr(0, character_start(s, max_bytes))) + "...";
}

std::string printable_lines(const std::string& text) {
  std::string out;
  size_t start = 0;
  for (size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1)
    out += printable(text.substr(start, end - start)) + "\n";
  return out + printable(text.substr(start));
}

std::string cpp_comment(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    const bool trigraph = c == '?' && i + 1 < s.size() && s[i + 1] == '?';
    if (c < 0x20 || c >= 0x7f || c == '\\' || c == '%' || trigraph) out += hex_byte(c, "%");
    else out += static_cast<char>(c);
  }
  return out;
}

std::string cpp_string_literal(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c < 0x20 || c >= 0x7f || c == '"' || c == '\\' || c == '?') {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\%03o", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

const std::string& checked_cpp_identifier(const std::string& s, const std::string& what) {
  bool ok = !s.empty() && !(s[0] >= '0' && s[0] <= '9') && s.find("__") == std::string::npos &&
            !(s[0] == '_' && s.size() > 1 && s[1] >= 'A' && s[1] <= 'Z') && !is_cpp_keyword(s);
  for (char c : s)
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
  if (!ok) throw std::invalid_argument(what + " '" + printable(s) + "' is not a valid C++ identifier");
  return s;
}

std::string shell_path(const std::string& path) {
  const std::string s = !path.empty() && path[0] == '-' ? "./" + path : path;
  static const std::string safe = "_./-+=:,@";
  // A word that starts with '=' is a command's path to zsh (its EQUALS option): quoted.
  bool plain = !s.empty() && s[0] != '=';
  for (char c : s)
    plain = plain && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      safe.find(c) != std::string::npos);
  if (plain) return s;
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

namespace {
// Whether `c` (one character as for_each_char gives it) shows as blank space: the ASCII blank,
// no-break and other Unicode spaces, zero-width characters and the byte-order mark. A
// spreadsheet may skip them before it looks for a formula's '='.
bool blank_looking(const std::string& c) {
  static const char* const kBlanks[] = {" ",            "\xC2\xA0",     "\xE1\x9A\x80", "\xE2\x80\xAF", "\xE2\x81\x9F",
                                        "\xE3\x80\x80", "\xEF\xBB\xBF", "\xE2\x81\xA0"};
  for (const char* b : kBlanks)
    if (c == b) return true;
  const auto u = [&](size_t i) { return static_cast<unsigned char>(c[i]); };
  return c.size() == 3 && u(0) == 0xE2 && u(1) == 0x80 && u(2) >= 0x80 && u(2) <= 0x8B;  // U+2000..U+200B
}

// Characters a font draws as nothing (beyond the blanks and controls): the zero-width joiners
// U+200C, U+200D, the soft hyphen U+00AD, the combining grapheme joiner U+034F, the invisible
// operators U+2061..U+2064, the variation selectors U+FE00..U+FE0F and the Hangul fillers
// U+115F, U+3164 (a review of visible_skeleton).
bool shows_as_nothing(const std::string& c) {
  const auto b = [&](size_t i) { return static_cast<unsigned char>(c[i]); };
  if (c.size() == 2) return (b(0) == 0xC2 && b(1) == 0xAD) || (b(0) == 0xCD && b(1) == 0x8F);
  if (c.size() != 3) return false;
  return (b(0) == 0xE2 && b(1) == 0x80 && (b(2) == 0x8C || b(2) == 0x8D)) ||
         (b(0) == 0xE2 && b(1) == 0x81 && b(2) >= 0xA1 && b(2) <= 0xA4) || (b(0) == 0xEF && b(1) == 0xB8 && b(2) <= 0x8F) ||
         (b(0) == 0xE1 && b(1) == 0x85 && b(2) == 0x9F) || (b(0) == 0xE3 && b(1) == 0x85 && b(2) == 0xA4);
}
}  // namespace

std::string visible_skeleton(const std::string& s) {
  std::string out;
  for_each_char(s, [&](const std::string& c) {
    if (!(c.size() == 1 && control(static_cast<unsigned char>(c[0]))) && !invisible_control(c) && !blank_looking(c) &&
        !shows_as_nothing(c))
      out += c;
  });
  return out;
}

namespace {
// One spoof checker for the process: configured once, then used read-only (ICU allows
// concurrent use of a const checker). nullptr where ICU cannot give one (its data missing):
// the skeleton falls back to the visible one rather than abort a report over a legend.
const USpoofChecker* confusable_checker() {
  static const USpoofChecker* const checker = []() -> const USpoofChecker* {
    UErrorCode status = U_ZERO_ERROR;
    USpoofChecker* sc = uspoof_open(&status);
    if (U_SUCCESS(status)) uspoof_setChecks(sc, USPOOF_CONFUSABLE, &status);
    if (U_SUCCESS(status)) return sc;
    if (sc) uspoof_close(sc);
    return nullptr;
  }();
  return checker;
}
}  // namespace

std::string lookalike_skeleton(const std::string& s) {
  const std::string visible = visible_skeleton(s);  // valid UTF-8: invalid bytes are '?' there
  if (!confusable_checker() || visible.size() > static_cast<size_t>(INT32_MAX / 8)) return visible;
  std::string out(visible.size() * 3 + 16, '\0');
  for (int attempt = 0; attempt < 2; ++attempt) {
    UErrorCode status = U_ZERO_ERROR;
    const int32_t n = uspoof_getSkeletonUTF8(confusable_checker(), 0, visible.data(), static_cast<int32_t>(visible.size()),
                                             out.data(), static_cast<int32_t>(out.size()), &status);
    if (status == U_BUFFER_OVERFLOW_ERROR) {
      out.assign(static_cast<size_t>(n) + 1, '\0');
      continue;
    }
    if (U_FAILURE(status)) return visible;  // no skeleton: the visible one still keeps most apart
    out.resize(static_cast<size_t>(n));
    return out;
  }
  return visible;
}

namespace {
// The characters of `s` beyond plain printable ASCII, each by code point, Unicode name and
// place ("U+0430 CYRILLIC SMALL LETTER A (character 1)"); the first five, then how many more
// (a name of a thousand look-alike letters must not make a message of a hundred kB).
std::string unusual_characters(const std::string& s) {
  constexpr size_t kShown = 5;
  std::vector<std::string> said;
  size_t position = 0, more = 0;
  for_each_char(s, [&](const std::string& c) {
    ++position;
    if (c.size() == 1 && !control(static_cast<unsigned char>(c[0]))) return;  // ASCII, or '?' for a byte not UTF-8
    if (said.size() == kShown) return void(++more);
    int32_t i = 0;
    UChar32 cp = 0;
    U8_NEXT(c.data(), i, static_cast<int32_t>(c.size()), cp);  // c is one valid character (for_each_char)
    char hex[16], name[128] = "";
    std::snprintf(hex, sizeof hex, "U+%04X", static_cast<unsigned>(cp));
    UErrorCode status = U_ZERO_ERROR;
    u_charName(cp, U_EXTENDED_CHAR_NAME, name, sizeof name, &status);  // "<control-001B>" for a control
    said.push_back(std::string(hex) + (U_SUCCESS(status) && name[0] ? std::string(" ") + name : "") + " (character " +
                   std::to_string(position) + ")");
  });
  const std::string out = joined(said);
  return more ? out + " and " + std::to_string(more) + " more" : out;
}
}  // namespace

std::string lookalike_note(const std::string& word, const std::string& near) {
  if (word == near || lookalike_skeleton(word) != lookalike_skeleton(near)) return "";
  const std::string in_word = unusual_characters(word), in_near = unusual_characters(near);
  std::string apart;
  if (!in_word.empty()) apart = "'" + printable(word) + "' has " + in_word;
  if (!in_near.empty()) apart += (apart.empty() ? "" : "; ") + ("'" + printable(near) + "' has " + in_near);
  return apart.empty() ? "" : " (they look alike, but " + apart + ")";
}

std::string csv_field(const std::string& s) {
  // The text as the file will hold it: control characters as spaces, the invisible ones shown.
  std::vector<std::string> chars;
  for_each_char(s, [&](const std::string& c) {
    if (c.size() == 1 && control(static_cast<unsigned char>(c[0]))) chars.push_back(" ");
    else if (invisible_control(c)) chars.push_back(printable(c));
    else chars.push_back(c);
  });
  // The first character a spreadsheet sees once what looks blank is skipped decides whether
  // it runs the field as a formula.
  size_t first = 0;
  while (first < chars.size() && blank_looking(chars[first])) ++first;
  std::string out = "\"";
  if (first < chars.size() && chars[first].size() == 1 && std::string("=+-@").find(chars[first][0]) != std::string::npos) out += '\'';
  for (const auto& c : chars) out += c == "\"" ? "\"\"" : c;
  return out + "\"";
}

std::string gnuplot_string(const std::string& s) {
  // gnuplot's SVG terminal writes & as &amp; except where "&#x" starts, which it passes on as a
  // character reference: a log named "x&#x202E;.csv" would reach the page as a bidi override,
  // "&#x0;" would break the SVG. Its & is written as the reference &#x26; (an &, shown as such).
  // It passes "]]>" and the noncharacters U+FFFE, U+FFFF on as they are, and XML allows
  // neither in text: the SVG would not parse. "]]>" is written "]] >", they "?".
  std::string safe;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s.compare(i, 3, "&#x") == 0) safe += "&#x26;";
    else if (s.compare(i, 3, "]]>") == 0) safe += "]] >", i += 2;
    else safe += s[i];
  }
  std::string out = "'";
  for_each_char(safe, [&](const std::string& c) {
    if (c == "'") out += "'.\"'\".'";  // see gnuplot_string's comment
    else if (c.size() == 1 && control(static_cast<unsigned char>(c[0]))) out += ' ';
    else if (invisible_control(c)) out += printable(c);  // shown, not obeyed, in the SVG and the page it lands in
    else if (c == "\xEF\xBF\xBE" || c == "\xEF\xBF\xBF") out += '?';
    else out += c;
  });
  return out + "'";
}

std::string gnuplot_svg_tooltips_mended(const std::string& svg) {
  static const std::string open = "<title>", close = "</title>", wrong = "&amp;#x26;", right = "&amp;";
  std::string out;
  out.reserve(svg.size());
  size_t done = 0;
  for (size_t at = svg.find(open); at != std::string::npos; at = svg.find(open, done)) {
    const size_t text = at + open.size(), end = svg.find(close, text);
    if (end == std::string::npos) break;
    out.append(svg, done, text - done);
    for (size_t i = text; i < end;) {
      if (svg.compare(i, wrong.size(), wrong) == 0) out += right, i += wrong.size();
      else out += svg[i++];
    }
    done = end;
  }
  return out.append(svg, done, std::string::npos);
}

namespace {
std::string html_escaped(const std::string& s, bool keep_lines) {
  std::string out;
  for_each_char(s, [&](const std::string& c) {
    if (c == "&") out += "&amp;";
    else if (c == "<") out += "&lt;";
    else if (c == ">") out += "&gt;";
    else if (c == "\"") out += "&quot;";
    else if (c == "'") out += "&#39;";
    else if (c == "\n" && keep_lines) out += c;
    else if (c == "\n" || c == "\t") out += ' ';
    else if (c.size() == 1 && control(static_cast<unsigned char>(c[0]))) return;
    else if (invisible_control(c)) out += printable(c);  // shown, not obeyed
    else out += c;
  });
  return out;
}
}  // namespace

std::string html_text(const std::string& s) { return html_escaped(s, false); }

std::string html_preformatted(const std::string& s) { return html_escaped(s, true); }

namespace {
// What Markdown output shows as a blank: blanks, line breaks and control characters become
// spaces or vanish in it.
bool markdown_blank(char c) { return c == ' ' || control(static_cast<unsigned char>(c)); }

// Whether the text, which starts with no blank, opens a block (heading, list item, rule,
// setext underline) where it starts a line: '#', '-' or '+' followed by a blank, the end or
// itself; '=' at all; digits then '.' or ')' followed by a blank or the end. Returns the
// position of the character to escape.
size_t block_opener(const std::string& s) {
  if (s.empty()) return std::string::npos;
  const auto blank_or_end = [&](size_t k) { return k >= s.size() || markdown_blank(s[k]); };
  const char c = s[0];
  if (c == '=') return 0;
  if ((c == '#' || c == '-' || c == '+') && (blank_or_end(1) || s[1] == c)) return 0;
  size_t k = 0;
  while (k < s.size() && s[k] >= '0' && s[k] <= '9') ++k;
  if (k > 0 && k < s.size() && (s[k] == '.' || s[k] == ')') && blank_or_end(k + 1)) return k;
  return std::string::npos;
}
}  // namespace

std::string markdown_text(const std::string& text) {
  // Blanks at the start go: four of them open a code block where the text starts a line.
  size_t start = 0;
  while (start < text.size() && markdown_blank(text[start])) ++start;
  const std::string s = text.substr(start);
  // Inline Markdown (and GitHub's $ math): these change how the text around them renders.
  // The ':' of "://" and the '.' of "www." too: GitHub turns a bare https://... or www....
  // into a link, and a link is what a hostile description wants. So does it name@host, and
  // its e-mail autolinks see through an escaped '@' (the text is joined before they are
  // looked for): a word joiner (U+2060, invisible) follows the '@', and no domain starts there.
  // < > & too: escaped so, no raw HTML or entity comes of them, and the raw file reads as
  // the text (a reviewer reads derivation.md in an editor too; "&lt;" and "&#39;" did not).
  static const std::string punctuation = "\\`*_[]|$~<>&";
  const size_t opener = block_opener(s);
  const auto after_www = [&](size_t at) {
    if (at < 3) return false;
    for (size_t k = at - 3; k < at; ++k)
      if (s[k] != 'w' && s[k] != 'W') return false;
    return true;
  };
  std::string out;
  size_t at = 0;
  for_each_char(s, [&](const std::string& c) {
    const bool scheme = c == ":" && s.compare(at + 1, 2, "//") == 0;
    const bool special = c.size() == 1 && (punctuation.find(c[0]) != std::string::npos || scheme || (c[0] == '.' && after_www(at)));
    if (c == "@") out += "\\@\xE2\x81\xA0";  // U+2060 WORD JOINER
    else if (special || at == opener) out += "\\" + c;
    else if (c == "'" || c == "\"") out += c;  // text, not an attribute: nothing to escape
    else out += html_text(c);
    at += c.size();
  });
  return out;
}

std::string markdown_code(const std::string& s) {
  const bool plain = printable(s) == s && s.find('`') == std::string::npos && s.find('|') == std::string::npos;
  return plain ? "`" + s + "`" : markdown_text(s);
}

std::string latex_math_text(const std::string& s) {
  std::string out;
  for_each_char(s, [&](const std::string& c) {
    if (c == "\\") out += "\\backslash{}";
    else if (c == "~") out += "\\sim{}";
    else if (c == "^") out += "\\wedge{}";
    else if (c == "{" || c == "}" || c == "$" || c == "&" || c == "#" || c == "_" || c == "%") out += "\\" + c;
    else if (c == " " || (c.size() == 1 && control(static_cast<unsigned char>(c[0])))) out += "\\ ";
    else out += c;
  });
  return out;
}

}  // namespace quadgen::output
