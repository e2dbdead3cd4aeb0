# Per-pixel statistics of independent renders, for the reference scripts (sourced; needs oiiotool).

# mean_and_variance TMP_DIR OUT_MEAN OUT_VARIANCE FILE...: per pixel, the mean of the images and
# the variance of that mean (the images' sample variance over their number).
mean_and_variance() {
  local tmp=$1 mean=$2 variance=$3 k
  shift 3
  k=$#
  local sum=() sumsq=() first=1
  for f in "$@"; do
    sum+=("$f" --ch R,G,B)
    sumsq+=("$f" --ch R,G,B --dup --mul)
    [ $first = 1 ] || { sum+=(--add); sumsq+=(--add); }
    first=0
  done
  oiiotool "${sum[@]}" -d float -o "$tmp/sum.exr"
  oiiotool "${sumsq[@]}" -d float -o "$tmp/sumsq.exr"
  oiiotool "$tmp/sum.exr" --divc "$k" -d float -o "$mean"
  oiiotool "$tmp/sumsq.exr" "$tmp/sum.exr" --dup --mul --divc "$k" --sub --divc "$((k * (k - 1)))" \
    --clamp:min=0 -d float -o "$variance"
}
