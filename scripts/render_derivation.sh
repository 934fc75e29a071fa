#!/usr/bin/env bash
# A derivation report as a reader sees it: derivation.md (```math blocks, $...$ inline) put
# into HTML with Debian's MathJax (libjs-mathjax; GitHub renders the same TeX with MathJax),
# rendered by headless Chromium, and the rendered page checked: no TeX error or undefined
# control sequence anywhere, every
# ```math block displayed, and the first matrix with all its rows (a `\\` that a Markdown
# pipeline ate collapses a matrix to one row). Exit 0 when it renders; 1 with the reason.
#   scripts/render_derivation.sh [DERIVATION.md ...]   (default: generated/*/derivation.md)
# Installs chromium and libjs-mathjax when missing (a developers' check; not in CI).
set -euo pipefail
cd "$(dirname "$0")/.."
files=("$@")
[ ${#files[@]} -gt 0 ] || files=(generated/*/derivation.md)
if ! command -v chromium > /dev/null || [ ! -f /usr/share/javascript/mathjax/MathJax.js ]; then
  echo "installing chromium and libjs-mathjax (Debian packages) for the check" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium libjs-mathjax fonts-mathjax > /dev/null
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
for md in "${files[@]}"; do
  [ -f "$md" ] || { echo "$md: no such file" >&2; status=1; continue; }
  html="$tmp/page.html"
  # Text is HTML-escaped; a ```math block becomes display math \[...\]; $...$ stays inline.
  python3 - "$md" "$html" <<'PY'
import html, re, sys
src = open(sys.argv[1], encoding="utf-8").read()
parts = re.split(r"^```math\n(.*?)\n```$", src, flags=re.S | re.M)
out = []
for i, part in enumerate(parts):
    if i % 2:
        out.append('<div class="display">\\[' + html.escape(part) + "\\]</div>")
    else:
        out.append("<pre>" + html.escape(part) + "</pre>")
page = """<!doctype html><html><head><meta charset="utf-8">
<script type="text/x-mathjax-config">
MathJax.Hub.Config({tex2jax: {inlineMath: [["$", "$"]], displayMath: [["\\\\[", "\\\\]"]], processEscapes: false},
  "CommonHTML": {linebreaks: {automatic: false}}, messageStyle: "none"});
MathJax.Hub.Queue(function () { document.body.setAttribute("data-typeset", "done"); });
</script>
<script src="file:///usr/share/javascript/mathjax/MathJax.js?config=TeX-AMS_CHTML"></script>
</head><body>""" + "\n".join(out) + "</body></html>"
open(sys.argv[2], "w", encoding="utf-8").write(page)
PY
  blocks=$(grep -c '^```math$' "$md" || true)
  chromium --headless --no-sandbox --disable-gpu --allow-file-access-from-files --user-data-dir="$tmp/profile" \
    --virtual-time-budget=60000 --dump-dom -- "file://$html" > "$tmp/dom.html" 2> /dev/null || true
  python3 - "$tmp/dom.html" "$blocks" "$md" <<'PY' || status=1
import re, sys
dom, blocks, md = open(sys.argv[1], encoding="utf-8").read(), int(sys.argv[2]), sys.argv[3]
problems = []
if 'data-typeset="done"' not in dom:
    problems.append("MathJax did not finish")
# A TeX error shows as merror, or with MathJax's noErrors extension as the raw TeX in a box
# (mjx-noError: e.g. a formula beyond MathJax's 5 KB input buffer, GitHub's limit too).
errors = len(re.findall(r'class="[^"]*\b(merror|MathJax_Error|mjx-merror|mjx-noError)\b', dom))
# An undefined control sequence (MathJax's noUndefined) is shown in red, not as an merror.
errors += len(re.findall(r'class="mjx-mtext[^"]*" style="color: red;', dom))
if errors:
    problems.append(f"{errors} TeX error(s)")
displays = dom.split('<div class="display">')[1:]
rendered = sum(1 for d in displays if "mjx-chtml" in d.split("</div>")[0] or "MJXc-display" in d)
if rendered != blocks:
    problems.append(f"{rendered} of {blocks} math blocks rendered")
if displays:
    rows = len(re.findall(r'class="mjx-mtr"', displays[0]))
    if rows < 3:
        problems.append(f"the first matrix rendered with {rows} rows (3 expected)")
print(f"{md}: " + ("renders: " + f"{blocks} math blocks, no TeX errors" if not problems else "; ".join(problems)))
sys.exit(1 if problems else 0)
PY
done
exit $status
