#!/usr/bin/env bash
# Installs the Debian packages quadgen builds with, only those that are missing.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libginac-dev libcln-dev ginac-tools   # symbolic derivation
  libeigen3-dev libceres-dev            # linear algebra, fitting
  libgtest-dev libbenchmark-dev         # tests, benchmarks
  libyaml-cpp-dev                       # vehicle files (keeps line numbers for error messages)
  libcli11-dev                          # command line
  nlohmann-json3-dev                    # model.json and friends
  libboost-math-dev                     # chi-squared quantiles for profile-likelihood thresholds; brings
                                        # libboost1.74-dev, whose Boost.Geometry the audit unites polygons with
  libssl-dev                            # SHA-256 of vehicle files (which generated header is whose)
  libkainjow-mustache-dev               # text templates for generated code
  libicu-dev                            # Unicode look-alike skeletons (flight labels that must not read alike)
  gnuplot-nox                           # plots (SVG) of simulations and fits
  python3                               # scripts/*.py (tables, checks; standard library only) and one test
  cmark-gfm                             # tests: hostile text rendered as GitHub renders Markdown
  clang libclang-rt-14-dev              # CI's sanitizer build (.ci/sanitize) and libFuzzer (scripts/fuzz.sh)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "installing: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "all build dependencies present"
fi
