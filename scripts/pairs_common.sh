# Sourced by the scripts that measure two builds side by side (build_pairs.sh, runtime_pairs.sh,
# performance.sh):
# - `needs_value NAME FLAG COUNT`: exits naming the calling script NAME when FLAG, an option that
#   takes a value, is the last argument (COUNT: the arguments left, FLAG included);
# - `whole_count NAME FLAG VALUE`: exits when VALUE is not a whole number from 1;
# - `median V...`: the median of the numbers V (the mean of the middle two for an even count);
# - `median_range V...`: the median and, in brackets, the least and the greatest.
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
