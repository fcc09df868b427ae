# Sourced by scripts/fetch-*.sh. `path_from_env SCRIPT VAR`: when VAR is set
# to a file, prints its path and exits 0; when VAR is set to anything else,
# says so on stderr as SCRIPT and exits 1; when VAR is unset or empty,
# returns and the script fetches its own copy.
path_from_env() {
    local script=$1 var=$2
    local value=${!var:-}
    if [[ -n "$value" ]]; then
        if [[ -f "$value" ]]; then
            echo "$value"
            exit 0
        fi
        echo "$script: $var is set to '$value', which is not a file" >&2
        exit 1
    fi
}
