# Shared by the bench scripts (sourced).

# The median of the numbers on stdin (separated by spaces or newlines), with six decimals.
median() {
  tr ' ' '\n' | grep -v '^$' | sort -g |
    awk '{a[NR]=$1} END{if(NR%2)printf "%.6f\n",a[(NR+1)/2]; else printf "%.6f\n",(a[NR/2]+a[NR/2+1])/2}'
}

# Exits (status 2) unless $1, the REPEATS a script was given, is a positive integer.
check_repeats() {
  [[ "$1" =~ ^[1-9][0-9]*$ ]] || { echo "$0: REPEATS must be a positive integer" >&2; exit 2; }
}

# The parapm program of PARAPM_BUILD_DIR (default $1/build, $1 the repository), or a message and
# status 2 when it is not built.
parapm_program() {
  local bin="${PARAPM_BUILD_DIR:-$1/build}/bin/parapm"
  [[ -x "$bin" ]] || { echo "no $bin (build the parapm target)" >&2; return 2; }
  echo "$bin"
}
