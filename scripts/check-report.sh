#!/usr/bin/env bash
# Renders an HTML report (finecap eval's report.html) in headless Chromium to a PNG and checks
# what a reader would see: every <img> of the report loads and decodes in the browser, every
# picture it refers to by file name exists and is a PNG or JPEG, and the screenshot exists and
# is not of a single colour. When the report has a 3D view (finecap eval's, with three.js), its
# canvas must show up within the screenshot and each of its panels (input | refined | truth, as
# labelled) must have drawn a shaded mesh: at least 2 % of its pixels off the background and at
# least 16 grey levels among them (a blank or flat-shaded canvas has one or a few). Every picture
# of a row of comparison panels (<figure class="panels">: the held-out photo beside what each mesh
# predicts there and their NCC maps) must show at least 8 colours. Each panel checked is listed
# by its label.
#
# Usage: scripts/check-report.sh REPORT.html OUT.png [WIDTH HEIGHT]
#   WIDTH x HEIGHT: the browser window, CSS pixels (default 1280 x 2000); the screenshot shows
#   the top of the page down to HEIGHT.
# Installs Debian's chromium when it is missing (apt-get; sudo when not root).
# Exit code 0 when every check passes; 1 with one message per problem otherwise; 77 when chromium
# cannot be installed or started (nothing was checked: tests report that as skipped).
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

unavailable() {
  echo "check-report: $*; nothing checked" >&2
  exit 77
}

install_chromium() {
  if ! command -v chromium >/dev/null; then
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    echo "check-report: installing chromium"
    { $sudo apt-get update -qq &&
      DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
        chromium fonts-dejavu-core >/dev/null; } || true
    command -v chromium >/dev/null || unavailable "chromium could not be installed"
  fi
  browser --dump-dom "data:text/html,<p>up</p>" | grep -q "<p>up</p>" ||
    unavailable "chromium does not start here (headless)"
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

# WebGL without a GPU: Chromium falls back to SwiftShader (software) with --disable-gpu; newer
# releases ask for --enable-unsafe-swiftshader to allow that fallback.
browser() {
  timeout 180 chromium --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader \
    --hide-scrollbars --allow-file-access-from-files --virtual-time-budget=10000 "$@" 2>/dev/null
}

# Runs `script` in a copy of `page` (resolving relative links against the report's folder) and
# prints the text the script leaves in the element with id "finecap-check".
run_in_page() {
  local page="$1" script="$2" copy
  copy="$(mktemp --suffix=.html)"
  {
    # After the doctype, so the copy is laid out as the page itself (not in quirks mode).
    if head -n 1 "$page" | grep -qi '^<!DOCTYPE'; then
      head -n 1 "$page"
      echo "<base href=\"file://$report_dir/\">"
      tail -n +2 "$page"
    else
      echo "<base href=\"file://$report_dir/\">"
      cat "$page"
    fi
    echo "<div id=\"finecap-check\"></div><script>$script</script>"
  } >"$copy"
  # At the screenshot's window size, so that layouts measured here are the screenshot's.
  browser --window-size="$width,$height" --dump-dom "file://$copy" | grep -o 'id="finecap-check">[^<]*' | sed 's/.*>//'
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

# The screenshot (the <img id="shot"> of the page) drawn into a 2D canvas, whose context it returns.
SHOT_CONTEXT='
function shotContext() {
  const image = document.getElementById("shot");
  const canvas = document.createElement("canvas");
  canvas.width = image.naturalWidth;
  canvas.height = image.naturalHeight;
  const context = canvas.getContext("2d");
  context.drawImage(image, 0, 0);
  return context;
}'

# The number of distinct colours of the screenshot (sampled on a grid), read through a canvas.
COLOURS_SCRIPT="$SHOT_CONTEXT"'
window.addEventListener("load", () => {
  const context = shotContext(), canvas = context.canvas;
  const pixels = context.getImageData(0, 0, canvas.width, canvas.height).data;
  const colours = new Set();
  const step = 4 * 7;
  for (let i = 0; i < pixels.length; i += step) {
    colours.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
  }
  document.getElementById("finecap-check").textContent =
      canvas.width + "x" + canvas.height + " " + colours.size;
});'

# The 3D view's canvas in page pixels and its panels' labels, "X Y WIDTH HEIGHT LABEL|LABEL|...";
# "none" when the page has none.
VIEWER_RECT_SCRIPT='
window.addEventListener("load", () => {
  const canvas = document.querySelector("#finecap-viewer canvas");
  const box = canvas ? canvas.getBoundingClientRect() : null;
  const labels = [...document.querySelectorAll("#finecap-viewer .viewer-label")]
      .map(label => label.dataset.panel.replace(/[|\s]+/g, "_"));
  document.getElementById("finecap-check").textContent = box
      ? [box.left + scrollX, box.top + scrollY, box.width, box.height].map(Math.round).join(" ") +
        " " + (labels.length ? labels.join("|") : "input|refined")
      : "none";
});'

# Each row of comparison panels: "ROW: LABEL COLOURS, LABEL COLOURS; ROW: ..." with the number of
# distinct colours of each picture (0 when it did not load), "none" when the page has none.
PANELS_SCRIPT='
window.addEventListener("load", () => {
  const rows = [...document.querySelectorAll("figure.panels")].map(row => {
    const panels = [...row.querySelectorAll("img[data-panel]")].map(image => {
      let colours = 0;
      if (image.complete && image.naturalWidth > 0) {
        const canvas = document.createElement("canvas");
        canvas.width = image.naturalWidth;
        canvas.height = image.naturalHeight;
        const context = canvas.getContext("2d");
        context.drawImage(image, 0, 0);
        const pixels = context.getImageData(0, 0, canvas.width, canvas.height).data;
        const seen = new Set();
        for (let i = 0; i < pixels.length; i += 4) {
          seen.add((pixels[i] << 16) | (pixels[i + 1] << 8) | pixels[i + 2]);
        }
        colours = seen.size;
      }
      return image.dataset.panel + " " + colours;
    });
    return row.dataset.panels + ": " + panels.join(", ");
  });
  document.getElementById("finecap-check").textContent = rows.length ? rows.join("; ") : "none";
});'

# For each panel of the canvas region of the screenshot (PANELS of them, side by side): the
# percentage of pixels off the background (the top-left pixel of the panel) and the number of
# grey levels among them, "PERCENT LEVELS PERCENT LEVELS ...". Each panel is inset by 4 pixels to
# skip the border, by 24 at the top to skip the labels.
VIEWER_PIXELS_SCRIPT="$SHOT_CONTEXT"'
window.addEventListener("load", () => {
  const [x, y, width, height] = "RECT".split(" ").map(Number);
  const count = PANELS;
  const context = shotContext();
  const halves = [...Array(count).keys()].map(half => {
    const left = x + 4 + Math.floor(half * width / count), top = y + 24;
    const w = Math.floor(width / count) - 8, h = height - 28;
    const pixels = context.getImageData(left, top, w, h).data;
    const background = [pixels[0], pixels[1], pixels[2]];
    const levels = new Set();
    let off = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      const difference = Math.max(...[0, 1, 2].map(c => Math.abs(pixels[i + c] - background[c])));
      if (difference <= 12) continue;
      ++off;
      levels.add(Math.round(0.299 * pixels[i] + 0.587 * pixels[i + 1] + 0.114 * pixels[i + 2]));
    }
    return (100 * off / (w * h)).toFixed(1) + " " + levels.size;
  });
  document.getElementById("finecap-check").textContent = halves.join(" ");
});'

# Checks the 3D view's canvas region of the screenshot `$1`; `$2` is its rectangle and the
# panels' labels.
check_viewer() {
  local shot="$1" rect labels page result
  read -r _ rect_y _ rect_height labels <<<"$2"
  rect="${2% *}"
  if [ $((rect_y + rect_height)) -gt "$height" ]; then
    echo "check-report: $report: the 3D view ($rect) is below the screenshot's $height pixels" >&2
    return 1
  fi
  local names=()
  IFS='|' read -r -a names <<<"$labels"
  page="$(mktemp --suffix=.html)"
  printf '<img id="shot" src="data:image/png;base64,%s">' "$(base64 -w0 "$shot")" >"$page"
  local script="${VIEWER_PIXELS_SCRIPT/RECT/$rect}"
  result="$(run_in_page "$page" "${script/PANELS/${#names[@]}}")"
  rm -f "$page"
  local values=()
  read -r -a values <<<"$result"
  if [ "${#values[@]}" -ne $((2 * ${#names[@]})) ]; then
    echo "check-report: $shot: the 3D view's region could not be read back" >&2
    return 1
  fi
  local problems=0 i share levels summary=""
  for i in "${!names[@]}"; do
    share="${values[$((2 * i))]}"
    levels="${values[$((2 * i + 1))]}"
    summary+="${summary:+; }${names[$i]} $share % of pixels drawn, $levels grey levels"
    if [ "${share%.*}" -lt 2 ] || [ "$levels" -lt 16 ]; then
      echo "check-report: $shot: the 3D view's panel '${names[$i]}' shows no shaded mesh" >&2
      problems=1
    fi
  done
  echo "check-report: 3D view: $summary"
  return $problems
}

# Checks every row of comparison panels of the report: each picture loaded and shows at least 8
# colours.
check_panels() {
  local rows row problems=0
  rows="$(run_in_page "$report_abs" "$PANELS_SCRIPT")"
  case "$rows" in
    none) echo "check-report: $report: no comparison panels"; return 0 ;;
    "") echo "check-report: $report: the browser reported nothing of the comparison panels" >&2
      return 1 ;;
  esac
  while IFS= read -r row; do
    echo "check-report: panels $row"
    local panel
    while IFS= read -r panel; do
      panel="${panel# }"
      if [ "${panel##* }" -lt 8 ]; then
        echo "check-report: $report: panel '${panel% *}' of '${row%%: *}' is blank" \
          "(${panel##* } colours)" >&2
        problems=1
      fi
    done < <(tr ',' '\n' <<<"${row#*: }")
  done <<<"${rows//; /$'\n'}"
  return $problems
}

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
viewer_rect="$(run_in_page "$report_abs" "$VIEWER_RECT_SCRIPT")"
case "$viewer_rect" in
  none) echo "check-report: $report: no 3D view" ;;
  "") echo "check-report: $report: the browser reported no layout for the 3D view" >&2
    problems=1 ;;
  *) check_viewer "$out_abs" "$viewer_rect" || problems=1 ;;
esac
check_panels || problems=1
[ "$problems" -eq 0 ] || exit 1
echo "check-report: ok"
