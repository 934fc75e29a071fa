"""One table cell of Markdown from a string the scripts did not write (a folder or file name):
shown as text, never as markup. Newlines, other controls and bidirectional marks become
spaces; the characters that end a cell (|), start markup (* _ ` [ ] ~ and the backslash) or
HTML (< > &) are escaped. The tables go into the README and docs, which GitHub renders.
terminal_text: the same string printed on a terminal, its controls and bidirectional marks
written as escapes (\\x1b, \\u202e), so that a file name cannot move the cursor, retitle the
window or reorder the line (as output::printable in the C++ sinks)."""

_ESCAPED = set("\\|*_`[]~")
# Shown as a space: the line and paragraph separators and the bidirectional controls and
# marks, which reorder what a reader sees (as output::invisible_control in the C++ sinks).
_INVISIBLE = set("\u2028\u2029\u200e\u200f\u061c\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069")


def cell(text):
    out = []
    for ch in str(text):
        if ord(ch) < 0x20 or 0x7F <= ord(ch) <= 0x9F or ch in _INVISIBLE:
            out.append(" ")
        elif ch == "<":
            out.append("&lt;")
        elif ch == ">":
            out.append("&gt;")
        elif ch == "&":
            out.append("&amp;")
        elif ch in _ESCAPED:
            out.append("\\" + ch)
        else:
            out.append(ch)
    return "".join(out)


def terminal_text(text):
    out = []
    for ch in str(text):
        if ord(ch) < 0x20 or 0x7F <= ord(ch) <= 0x9F:
            out.append(f"\\x{ord(ch):02x}")
        elif ch in _INVISIBLE:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return "".join(out)


if __name__ == "__main__":  # a self-check: python3 scripts/markdown_cell.py
    assert cell("x|y<img src=x onerror=alert(1)>") == "x\\|y&lt;img src=x onerror=alert(1)&gt;"
    assert cell("B3_figure8\nrep2") == "B3\\_figure8 rep2"
    assert cell("plain name 1.5") == "plain name 1.5"
    assert cell("a\u202ecba") == "a cba"
    assert terminal_text("B\x1b[31mRED\x07\u202e.csv") == "B\\x1b[31mRED\\x07\\u202e.csv"
    print("ok")
