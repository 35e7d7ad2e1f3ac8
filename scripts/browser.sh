# Sourced by the scripts that render with headless Chromium: `find_browser NAME` sets `browser`
# to PLUMETRACE_BROWSER or Debian's chromium-headless-shell (or chromium), and exits naming the
# calling script NAME when there is none or it cannot be run.
find_browser() {
    browser="${PLUMETRACE_BROWSER:-$(command -v chromium-headless-shell || command -v chromium || true)}"
    if [ -z "$browser" ]; then
        echo "$1: no headless Chromium: install chromium-headless-shell or set PLUMETRACE_BROWSER" >&2
        exit 1
    fi
    if [ ! -x "$browser" ]; then
        echo "$1: the browser $browser is not an executable file (PLUMETRACE_BROWSER?)" >&2
        exit 1
    fi
}
