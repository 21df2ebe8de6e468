#!/usr/bin/env bash
# Renders an HTML report (finecap eval's report.html) in headless Chromium to a PNG and checks
# what a reader would see: every <img> of the report loads and decodes in the browser, every
# picture it refers to by file name exists and is a PNG or JPEG, and the screenshot exists and
# is not of a single colour.
#
# Usage: scripts/check-report.sh REPORT.html OUT.png [WIDTH HEIGHT]
#   WIDTH x HEIGHT: the browser window, CSS pixels (default 1280 x 2000); the screenshot shows
#   the top of the page down to HEIGHT.
# Installs Debian's chromium when it is missing (apt-get; sudo when not root).
# Exit code 0 when every check passes; 1 with one message per problem otherwise.
set -euo pipefail

fail() {
  echo "check-report: $*" >&2
  exit 1
}

[ $# -eq 2 ] || [ $# -eq 4 ] || fail "usage: $0 REPORT.html OUT.png [WIDTH HEIGHT]"
report="$1"
out="$2"
width="${3:-1280}"
height="${4:-2000}"
[ -f "$report" ] || fail "$report: no such file"
[[ "$width" =~ ^[0-9]+$ && "$height" =~ ^[0-9]+$ ]] || fail "WIDTH and HEIGHT must be integers"
[ -e "$out" ] && fail "$out: exists already; give a new file name (nothing is overwritten)"
report_dir="$(cd "$(dirname "$report")" && pwd)"
report_abs="$report_dir/$(basename "$report")"
out_abs="$(cd "$(dirname "$out")" && pwd)/$(basename "$out")"

install_chromium() {
  command -v chromium >/dev/null && return
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "check-report: installing chromium"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    chromium fonts-dejavu-core >/dev/null
  command -v chromium >/dev/null || fail "chromium could not be installed"
}

# The first bytes of a PNG or a JPEG file.
is_png_or_jpeg() {
  local magic
  magic="$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')"
  [[ "$magic" == 89504e470d0a1a0a* || "$magic" == ffd8ff* ]]
}

# Pictures referred to by file name must exist next to the report and be PNG or JPEG.
check_referenced_files() {
  local source problems=0
  while IFS= read -r source; do
    [[ "$source" == data:* || "$source" == http:* || "$source" == https:* ]] && continue
    local path="$report_dir/${source#file://}"
    [[ "$source" == /* || "$source" == file://* ]] && path="${source#file://}"
    if [ ! -f "$path" ]; then
      echo "check-report: $report: picture $source is missing" >&2
      problems=1
    elif ! is_png_or_jpeg "$path"; then
      echo "check-report: $report: picture $source is neither PNG nor JPEG" >&2
      problems=1
    fi
  done < <(grep -o '<img[^>]*src="[^"]*"' "$report" | sed 's/.*src="\([^"]*\)"/\1/')
  return $problems
}

browser() {
  timeout 180 chromium --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --allow-file-access-from-files --virtual-time-budget=10000 "$@" 2>/dev/null
}

# Runs `script` in a copy of `page` (resolving relative links against the report's folder) and
# prints the text the script leaves in the element with id "finecap-check".
run_in_page() {
  local page="$1" script="$2" copy
  copy="$(mktemp --suffix=.html)"
  {
    echo "<base href=\"file://$report_dir/\">"
    cat "$page"
    echo "<div id=\"finecap-check\"></div><script>$script</script>"
  } >"$copy"
  browser --dump-dom "file://$copy" | grep -o 'id="finecap-check">[^<]*' | sed 's/.*>//'
  rm -f "$copy"
}

# Names of the <img> elements that failed to load or decode, or "all N loaded".
IMAGES_SCRIPT='
window.addEventListener("load", () => {
  const images = [...document.images].filter(i => !i.closest("#finecap-check"));
  const broken = images.filter(i => !i.complete || i.naturalWidth === 0);
  document.getElementById("finecap-check").textContent = broken.length === 0
      ? "all " + images.length + " loaded"
      : "broken: " + broken.map(i => i.alt || i.src.slice(0, 60)).join("; ");
});'

# The number of distinct colours of the screenshot (sampled on a grid), read through a canvas.
COLOURS_SCRIPT='
window.addEventListener("load", () => {
  const image = document.getElementById("shot");
  const canvas = document.createElement("canvas");
  canvas.width = image.naturalWidth;
  canvas.height = image.naturalHeight;
  const context = canvas.getContext("2d");
  context.drawImage(image, 0, 0);
  const pixels = context.getImageData(0, 0, canvas.width, canvas.height).data;
  const colours = new Set();
  const step = 4 * 7;
  for (let i = 0; i < pixels.length; i += step) {
    colours.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
  }
  document.getElementById("finecap-check").textContent =
      canvas.width + "x" + canvas.height + " " + colours.size;
});'

install_chromium
problems=0
check_referenced_files || problems=1

images="$(run_in_page "$report_abs" "$IMAGES_SCRIPT")"
case "$images" in
  "all "*" loaded") echo "check-report: $report: $images pictures" ;;
  "") echo "check-report: $report: the browser reported nothing (did the page load?)" >&2
    problems=1 ;;
  *) echo "check-report: $report: pictures that did not load: ${images#broken: }" >&2
    problems=1 ;;
esac

browser --window-size="$width,$height" --screenshot="$out_abs" "file://$report_abs" >/dev/null
[ -s "$out_abs" ] || fail "$report: chromium wrote no screenshot to $out"
is_png_or_jpeg "$out_abs" || fail "$out: the screenshot is not a PNG"
shot_page="$(mktemp --suffix=.html)"
printf '<img id="shot" src="data:image/png;base64,%s">' "$(base64 -w0 "$out_abs")" >"$shot_page"
read -r size colours <<<"$(run_in_page "$shot_page" "$COLOURS_SCRIPT")"
rm -f "$shot_page"
if [ -z "${colours:-}" ]; then
  echo "check-report: $out: the screenshot could not be read back" >&2
  problems=1
elif [ "$colours" -le 1 ]; then
  echo "check-report: $out: the screenshot is blank (a single colour)" >&2
  problems=1
else
  echo "check-report: $out: $size pixels, $colours colours"
fi
[ "$problems" -eq 0 ] || exit 1
echo "check-report: ok"
