#!/bin/sh
# Renders an artcal HTML report (or an SVG figure) to a PNG with headless Chromium, so that anyone
# can look at what the report shows. Not part of the test run.
#
#   tools/render_report.sh REPORT.html OUT.png [WIDTHxHEIGHT]
#
# The default window is 1000 px wide (about A4 at 120 dpi) and tall enough for the whole report.
# Installs Debian's `chromium` with apt-get when it is missing (needs root).
set -eu

if [ $# -lt 2 ]; then
  echo "usage: $0 REPORT.html OUT.png [WIDTHxHEIGHT]" >&2
  exit 2
fi
report=$1
out=$2
size=${3:-1000x6000}

if [ ! -r "$report" ]; then
  echo "error: $report: cannot read" >&2
  exit 2
fi

browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
  echo "chromium not found; installing Debian's chromium with apt-get" >&2
  if [ "$(id -u)" -ne 0 ]; then
    echo "error: run as root, or install chromium first (apt-get install chromium)" >&2
    exit 2
  fi
  DEBIAN_FRONTEND=noninteractive apt-get update -q
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends chromium
  browser=$(command -v chromium)
fi

profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
abs_report=$(cd "$(dirname "$report")" && pwd)/$(basename "$report")
case "$out" in
  /*) abs_out=$out ;;
  *) abs_out=$(pwd)/$out ;;
esac
width=${size%x*}
height=${size#*x}

"$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --hide-scrollbars --user-data-dir="$profile" \
  --window-size="$width,$height" --screenshot="$abs_out" "file://$abs_report" \
  >/dev/null 2>&1 || {
  echo "error: chromium failed to render $report" >&2
  exit 1
}
[ -s "$abs_out" ] || {
  echo "error: no screenshot written to $out" >&2
  exit 1
}
echo "$out"
