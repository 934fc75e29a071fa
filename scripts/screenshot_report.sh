#!/usr/bin/env bash
# A report as a person sees it: headless Chromium renders an HTML report (a diagnosis'
# report.html) to a PNG at a laptop's width, so a layout that runs off the page or a plot
# that does not load shows before a user finds it.
#   scripts/screenshot_report.sh REPORT.html OUT.png [WIDTH [HEIGHT]]   (default 1280 x 4000)
# Installs Debian's chromium when missing (a check for developers, not one of the README's
# two commands). Not in CI.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 REPORT.html OUT.png [WIDTH [HEIGHT]]" >&2; exit 2; }
report=$1 out=$2 width=${3:-1280} height=${4:-4000}
[[ $width =~ ^[0-9]+$ && $height =~ ^[0-9]+$ ]] || { echo "$0: WIDTH and HEIGHT are whole numbers of pixels" >&2; exit 2; }
[ -f "$report" ] || { echo "$0: $report: no such file" >&2; exit 1; }
if ! command -v chromium > /dev/null; then
  echo "installing chromium (Debian package) for the screenshot" >&2
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium > /dev/null
fi
# The report's path as a file:// URL, every byte that is not plain percent-encoded (a path
# is data here, never part of a command line Chromium parses as options).
url=$(python3 -c 'import pathlib, sys; print(pathlib.Path(sys.argv[1]).resolve().as_uri())' "$report")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# --allow-file-access-from-files: the report links its plots (SVG) beside it.
chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --allow-file-access-from-files \
  --user-data-dir="$tmp/profile" --window-size="$width,$height" --screenshot="$tmp/shot.png" -- "$url" > /dev/null 2>&1
[ -s "$tmp/shot.png" ] || { echo "$0: chromium wrote no screenshot" >&2; exit 1; }
mv "$tmp/shot.png" "$out"
echo "wrote $out (${width}x${height})"
