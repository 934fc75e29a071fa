// The documentation's links: every relative link in README.md and docs/*.md names a file that
// exists, and every #anchor a heading of the file it points into. The docs are long and move
// sections between files; a broken anchor only shows on the rendered page, so it is checked
// here (no network: links to other sites are not followed).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The lines of a Markdown file outside fenced code blocks (``` or ~~~), with their numbers.
std::vector<std::pair<int, std::string>> prose_lines(const std::string& text) {
  std::vector<std::pair<int, std::string>> out;
  std::istringstream in(text);
  bool fenced = false;
  int n = 0;
  for (std::string line; std::getline(in, line);) {
    ++n;
    const size_t first = line.find_first_not_of(' ');
    if (first != std::string::npos && (line.compare(first, 3, "```") == 0 || line.compare(first, 3, "~~~") == 0)) {
      fenced = !fenced;
      continue;
    }
    if (!fenced) out.emplace_back(n, line);
  }
  return out;
}

// One UTF-8 code point from s at i (advancing i); a malformed byte is returned as itself.
char32_t next_code_point(const std::string& s, size_t& i) {
  const auto b = static_cast<unsigned char>(s[i++]);
  int extra = b >= 0xF0 ? 3 : b >= 0xE0 ? 2 : b >= 0xC0 ? 1 : 0;
  char32_t c = extra == 3 ? b & 0x07 : extra == 2 ? b & 0x0F : extra == 1 ? b & 0x1F : b;
  for (; extra > 0 && i < s.size(); --extra) c = (c << 6) | (static_cast<unsigned char>(s[i++]) & 0x3F);
  return c;
}

void append_utf8(std::string& out, char32_t c) {
  if (c < 0x80) {
    out += static_cast<char>(c);
  } else if (c < 0x800) {
    out += static_cast<char>(0xC0 | (c >> 6)), out += static_cast<char>(0x80 | (c & 0x3F));
  } else {
    out += static_cast<char>(0xE0 | (c >> 12)), out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (c & 0x3F));
  }
}

// GitHub's anchor of a heading: trimmed, lower case; letters, digits, '_', '-' and spaces
// kept, spaces turned into '-', everything else (punctuation, symbols, dashes, backquotes,
// superscript digits) dropped. Of the non-ASCII letters only those the docs may use are
// known here: Latin-1, Latin Extended and Greek kept, the Latin-1 and Greek capitals lower-
// cased. A link to a heading beyond that (a Cyrillic word, a capital Ł) fails the check
// below, which then needs this function extended, not the link changed.
std::string anchor_of(std::string heading) {
  heading.erase(heading.find_last_not_of(" \t") + 1);
  heading.erase(0, std::min(heading.size(), heading.find_first_not_of(" \t")));
  // A link in a heading counts by its text: "[text](target)" -> "text".
  for (size_t open; (open = heading.find("](")) != std::string::npos;) {
    const size_t close = heading.find(')', open);
    if (close == std::string::npos) break;
    heading.erase(open + 1, close - open);
  }
  std::string out;
  for (size_t i = 0; i < heading.size();) {
    char32_t c = next_code_point(heading, i);
    if (c < 0x80) {
      const char a = static_cast<char>(c);
      if (std::isalnum(static_cast<unsigned char>(a)) || a == '_' || a == '-') out += static_cast<char>(std::tolower(a));
      if (a == ' ') out += '-';
      continue;
    }
    const bool latin = (c >= 0xC0 && c <= 0x24F && c != 0xD7 && c != 0xF7);
    const bool greek = c >= 0x391 && c <= 0x3C9;
    if (!latin && !greek) continue;
    if ((c >= 0xC0 && c <= 0xDE && c != 0xD7) || (c >= 0x391 && c <= 0x3A9)) c += 0x20;
    append_utf8(out, c);
  }
  return out;
}

// The anchors of a Markdown file's headings (ATX "#" headings outside code), a repeated one
// numbered "-1", "-2" as GitHub does, and explicit <a id="…"> / <a name="…"> anchors.
std::set<std::string> anchors_in(const std::string& text) {
  std::set<std::string> out;
  std::map<std::string, int> seen;
  for (const auto& [n, line] : prose_lines(text)) {
    for (const char* attr : {"<a id=\"", "<a name=\""})
      for (size_t at = line.find(attr); at != std::string::npos; at = line.find(attr, at + 1)) {
        const size_t begin = at + std::string(attr).size(), end = line.find('"', begin);
        if (end != std::string::npos) out.insert(line.substr(begin, end - begin));
      }
    size_t hashes = 0;
    while (hashes < line.size() && line[hashes] == '#') ++hashes;
    if (hashes == 0 || hashes > 6 || hashes >= line.size() || line[hashes] != ' ') continue;
    std::string a = anchor_of(line.substr(hashes + 1));
    const int k = seen[a]++;
    if (k > 0) a += "-" + std::to_string(k);
    out.insert(a);
  }
  return out;
}

// The targets of the inline links "[text](target)" on a line, inline code spans skipped.
std::vector<std::string> link_targets(const std::string& line) {
  std::vector<std::string> out;
  bool code = false;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    if (line[i] == '`') code = !code;
    if (code || line[i] != ']' || line[i + 1] != '(') continue;
    const size_t end = line.find(')', i + 2);
    if (end == std::string::npos) break;
    std::string t = line.substr(i + 2, end - i - 2);
    if (const size_t space = t.find(' '); space != std::string::npos) t.resize(space);  // [x](url "title")
    out.push_back(t);
    i = end;
  }
  return out;
}

struct Document {
  fs::path path;
  std::string text;
};

std::vector<Document> documents() {
  const fs::path root = QUADGEN_SOURCE_DIR;
  std::vector<Document> out{{root / "README.md", read(root / "README.md")}};
  std::vector<fs::path> docs;
  for (const auto& e : fs::directory_iterator(root / "docs"))
    if (e.path().extension() == ".md") docs.push_back(e.path());
  std::sort(docs.begin(), docs.end());
  for (const auto& p : docs) out.push_back({p, read(p)});
  return out;
}

}  // namespace

TEST(Docs, AnchorsAreGitHubs) {
  EXPECT_EQ(anchor_of("Fit on some flights, predict another (`scripts/cross_flight.sh`)"),
            "fit-on-some-flights-predict-another-scriptscross_flightsh");
  EXPECT_EQ(anchor_of("8. The answer — re-measured (2026-11-28, eighteenth session)"),
            "8-the-answer--re-measured-2026-11-28-eighteenth-session");
  EXPECT_EQ(anchor_of("Förster's τ ≤ 2 m/s²"), "försters-τ--2-ms");
  EXPECT_EQ(anchor_of("Trailing blank "), "trailing-blank");
  EXPECT_EQ(anchor_of("See [the table](x.md#y) here"), "see-the-table-here");
  const std::set<std::string> twice = anchors_in("# A\n```\n# not a heading\n```\n## A\n#nospace\n");
  EXPECT_EQ(twice, (std::set<std::string>{"a", "a-1"}));
}

TEST(Docs, EveryRelativeLinkAndAnchorResolves) {
  const std::vector<Document> docs = documents();
  std::map<fs::path, std::set<std::string>> anchors;
  for (const auto& d : docs) anchors[fs::weakly_canonical(d.path)] = anchors_in(d.text);
  size_t checked = 0;
  for (const auto& d : docs)
    for (const auto& [n, line] : prose_lines(d.text))
      for (const std::string& target : link_targets(line)) {
        if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0) continue;
        const std::string where = d.path.filename().string() + ":" + std::to_string(n) + ": " + target;
        const size_t hash = target.find('#');
        const std::string file = target.substr(0, hash);
        const fs::path p = file.empty() ? d.path : fs::weakly_canonical(d.path.parent_path() / file);
        ++checked;
        if (!file.empty() && !fs::exists(p)) {
          ADD_FAILURE() << where << ": no such file";
          continue;
        }
        if (hash == std::string::npos || p.extension() != ".md") continue;
        const fs::path key = fs::weakly_canonical(p);
        if (!anchors.count(key)) anchors[key] = anchors_in(read(key));
        EXPECT_TRUE(anchors[key].count(target.substr(hash + 1))) << where << ": no heading with this anchor";
      }
  EXPECT_GT(checked, 100u);  // the docs link to each other a great deal; none found means the parser broke
}
