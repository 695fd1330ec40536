# Shared by the bench scripts (sourced).

# The median of the numbers on stdin (separated by spaces or newlines), with six decimals.
median() {
  tr ' ' '\n' | grep -v '^$' | sort -g |
    awk '{a[NR]=$1} END{if(NR%2)printf "%.6f\n",a[(NR+1)/2]; else printf "%.6f\n",(a[NR/2]+a[NR/2+1])/2}'
}
