# Shared by run.sh and study.sh (sourced after `cd` to the repository root): the binary, the original data, the
# output folder, the original material and displacement names of each pattern, and the patterns asked for
# ($@, default all five). Exits 0 with a message when the original data are absent.
HYLC=${HYLC:-target/release/hylc}
D=${HYLC_SHARED:-../shared}/data/hylc2020
OUT=validation/identify
if [ ! -d "$D" ]; then
  echo "skipped: $D not found (set HYLC_SHARED)"; exit 0
fi
declare -A MAT=([basket]=basket1 [satin]=satin1 [slip_stitch_honeycomb]=honey1 [stockinette]=stock1 [cartridge_belt_rib]=rib1)
declare -A DISP=([basket]=basket [satin]=satin [slip_stitch_honeycomb]=honey [stockinette]=stock [cartridge_belt_rib]=rib)
PATTERNS=("$@")
[ ${#PATTERNS[@]} -eq 0 ] && PATTERNS=(basket satin slip_stitch_honeycomb stockinette cartridge_belt_rib)
