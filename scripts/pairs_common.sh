# Sourced by the scripts that measure two builds side by side (build_pairs.sh, runtime_pairs.sh,
# performance.sh) and by plume_step_parts.sh:
# - `needs_value NAME FLAG COUNT`: exits naming the calling script NAME when FLAG, an option that
#   takes a value, is the last argument (COUNT: the arguments left, FLAG included);
# - `whole_count NAME FLAG VALUE`: exits when VALUE is not a whole number from 1;
# - `median V...`: the median of the numbers V (the mean of the middle two for an even count);
# - `median_range V...`: the median and, in brackets, the least and the greatest;
# - `write_section PAGE FILE BEGIN END HEADING`: puts FILE's text (which starts with the mark BEGIN
#   and ends with END) in PAGE in place of what lies between those marks, or at PAGE's end under
#   `## HEADING` when PAGE has no such marks yet.
needs_value() {
    if [ "$3" -lt 2 ]; then
        echo "$1: $2 needs a value (see --help)" >&2
        exit 2
    fi
}

whole_count() {
    if ! [[ "$3" =~ ^[1-9][0-9]*$ ]]; then
        echo "$1: $2 takes a whole number from 1, not '$3'" >&2
        exit 2
    fi
}

median() {
    printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END {
        if (NR % 2) print v[(NR + 1) / 2]; else printf "%.3f", (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

median_range() {
    local sorted
    sorted=$(printf '%s\n' "$@" | sort -g)
    echo "$(median "$@") ($(head -1 <<<"$sorted")-$(tail -1 <<<"$sorted"))"
}

write_section() {
    python3 - "$@" <<'PY'
import sys
page, section, begin, end, heading = sys.argv[1:6]
text = open(page).read()
new = open(section).read().rstrip("\n")
if begin in text and end in text:
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    text = head + new + tail
else:
    text = text.rstrip("\n") + f"\n\n## {heading}\n\n" + new + "\n"
open(page, "w").write(text)
PY
}
