// Escaping at every place text leaves the program. Names are validated where they are read
// (output/names.hpp), and every sink escapes again, so that a string that slipped past one check
// (a path from the command line, a description, a future field) stays text wherever it lands.
// Each function returns text that is inert in its sink: it cannot end a comment, a string, a
// line of script or an element, whatever bytes it was given.
#pragma once
#include <string>

namespace quadgen::output {

// One line for a terminal or a log: control characters (newline, escape sequences; the C1
// controls and the bidirectional overrides in their UTF-8 form too) become \xNN, invalid
// UTF-8 becomes '?'.
std::string printable(const std::string& s);
// An error message for a terminal, as printable makes it, from at most about 1.7 kB of it (each
// control character then shown as \xNN, four bytes): a message
// quoting a 200 kB name (a vehicle file's block, a log's column) keeps its head (where and
// what) and its tail (what was expected), and says how many bytes it left out between them.
std::string printable_error(const std::string& message);
// The first at most `max_bytes` of `s` ending on a whole UTF-8 character, as printable makes
// it, and "..." after it where something was cut (a quoted cell of a log).
std::string printable_head(const std::string& s, size_t max_bytes);
// Several lines for a terminal (a command's summary): each line as printable makes it, the
// line breaks kept. Summaries quote log paths, which may carry escape sequences.
std::string printable_lines(const std::string& text);
// What of `s` every sink shows alike: its characters without the control characters (a sink
// shows them as spaces, or drops them), the invisible ones (bidirectional controls,
// zero-width characters, the soft hyphen, variation selectors) and whatever looks blank. Two names with one skeleton may read the
// same in some sink: a caller that must keep them apart (a plot's series) numbers them.
std::string visible_skeleton(const std::string& s);
// visible_skeleton, then Unicode's confusable skeleton (UTS #39, by ICU's spoof checker): two
// strings with one lookalike_skeleton may look the same to a reader even where every sink
// shows their characters faithfully: "é" written as one character or as e and a combining
// accent (NFC, NFD), a Latin "a" and a Cyrillic "а", "rn" and "m", "l" and "1". Coarser than
// the visible skeleton: a caller numbering series that must be told apart uses this one.
std::string lookalike_skeleton(const std::string& s);
// What an error adds after suggesting `near` for `word` where the two look alike (one
// lookalike_skeleton) but differ: what sets them apart, each one's characters beyond plain
// ASCII by code point, Unicode name and place (" (they look alike, but 'аy' has U+0430
// CYRILLIC SMALL LETTER A (character 1))"; the candidate's too, where the odd letter is in the
// log's header and not in the user's word; five at most a side); "" where they do not look
// alike, are equal, or differ only in ASCII ("rn" and "m"). An error that refuses 'аy' and
// suggests 'ay' reads as nonsense without it.
std::string lookalike_note(const std::string& word, const std::string& near);

// Text inside a C++ // comment on one line: ASCII printable characters stay, except '\' (a
// trailing one would splice the next line into the comment), '%' and '?' before '?' (trigraphs);
// those and every other byte become %XX.
std::string cpp_comment(const std::string& s);

// A C++ string literal, quotes included; anything but plain printable ASCII is an octal escape.
std::string cpp_string_literal(const std::string& s);

// `s` if it is a C++ identifier that is not a keyword or reserved name (leading '_', "__");
// throws std::invalid_argument naming `what` otherwise. The generator's last line of defence.
const std::string& checked_cpp_identifier(const std::string& s, const std::string& what);

// A gnuplot string expression of single-quoted strings, quotes included. Inside single quotes
// gnuplot expands neither backquotes nor macros. Its one escape there ('' for ') fails where
// the quote opens the text or follows one ("'b.csv" read as '' and then b.csv: the plot was
// lost, a hostile-input review, helper-146), so each ' is its own double-quoted string joined
// by gnuplot's '.' ('it'."'".'s'), which every label context takes. Control characters, which would end
// the command line, become spaces, and the bidirectional controls are shown as \xNN (as
// printable does): the SVG gnuplot writes lands in report.html. The & of "&#x", which the SVG
// terminal would pass on as a character reference, is written as &#x26; (shown as &). Labels
// are set `noenhanced`, so _ ^ @ { } stay literal.
std::string gnuplot_string(const std::string& s);

// The SVG gnuplot wrote from gnuplot_string labels, its tooltips mended: gnuplot escapes every
// & of a <title> element (the tooltip a browser shows), the "&#x" of drawn text it does not, so
// the &#x26; written for drawn text shows in the tooltip as "&#x26;". Inside <title> elements
// "&amp;#x26;" becomes "&amp;" (each such sequence there is one gnuplot_string wrote).
std::string gnuplot_svg_tooltips_mended(const std::string& svg);

// HTML text or attribute value: & < > " ' as entities, control characters dropped, the
// bidirectional controls shown as \xNN (as printable does) instead of reordering the text.
std::string html_text(const std::string& s);

// HTML text inside <pre>: as html_text, but line breaks stay.
std::string html_preformatted(const std::string& s);

// Markdown text on one line (table cells, headings): Markdown punctuation and the HTML
// characters < > & backslash-escaped (CommonMark's escapes: the raw file reads as the text,
// "a \< b" where an entity would read "a &lt; b"; quotes, which only an HTML attribute
// needs escaped, stay as they are), control characters as html_text has them; what would open a heading, a list or a rule
// at the start of a line (# - + = "1.") is escaped there, and blanks there dropped (four
// would open a code block); no bare URL, www. address or e-mail address is left for GitHub
// to turn into a link (the : of :// and the . after www escaped, @ escaped and followed by
// an invisible word joiner, U+2060, which no domain starts with).
std::string markdown_text(const std::string& s);

// Inline code (`name`) when `s` can be one (no backtick, no control character); otherwise the
// same text escaped as markdown_text.
std::string markdown_code(const std::string& s);

// A name inside \mathrm{...} or \operatorname{...} in math mode (derivation.md's math blocks,
// which GitHub renders with MathJax): TeX's ten special characters as the commands math mode
// has (\_ \{ \} \$ \& \# \%, \backslash, \sim, and \wedge for ^: the text-mode
// \textbackslash and kin are errors there), a control character as a space "\ ".
std::string latex_math_text(const std::string& s);

// A path as one word of a POSIX shell command line: itself when it holds only characters no
// shell acts on (letters, digits, _ . / - + = : , @), else single-quoted (a ' inside as
// '\''); one that starts with '-' gets "./" first, so that no command reads it as an option.
std::string shell_path(const std::string& path);

// A CSV field (RFC 4180), quotes included: '"' doubled, control characters (a line break would
// start a new record) as spaces, bidirectional controls shown as \xNN, invalid UTF-8 as '?'; a
// field that a spreadsheet would run as a formula (= + - @ first, after anything that looks
// blank: spaces, controls, Unicode spaces, zero-width characters) gets a leading apostrophe.
std::string csv_field(const std::string& s);

}  // namespace quadgen::output
