#!/bin/bash
# The held-out figures of docs/planes.md, "A peer's humanoid data": the FIGAROH talos_table_contact
# example's real touches (its data/real folder: left_train.csv, left_validation.csv,
# right_train.csv, right_validation.csv) calibrated with the plain commands, each hand alone and
# both together, without a prior and with each --prior; the held-out session scored in the
# calibration's frame (height mm, roll and pitch deg, RMS).
# Usage: tools/talos_figures.sh ARTCAL DATA_DIR URDF
set -euo pipefail
A=$(realpath "$1"); DATA=$(realpath "$2"); URDF=$(realpath "$3")
WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT; cd "$WORK"
echo '{"table": {"type": "plane", "measures": "flush", "axis": [0, 0, -1], "u_tilt": 0.1}}' > table.json
U="--urdf $URDF --unit rad --artifact table.json"
L="--base left_sole_link --tip gripper_left_base_link"
R="--base right_sole_link --tip gripper_right_base_link"
B="--base left_sole_link --tip gripper_left_base_link --tip gripper_right_base_link"
TIPS="--tip-of left_train=gripper_left_base_link --tip-of right_train=gripper_right_base_link"
VTIPS="--tip-of left_validation=gripper_left_base_link --tip-of right_validation=gripper_right_base_link"
figures() {
  "$A" verify "$@" --json 2>/dev/null | python3 -c "
import json, sys
for p in json.load(sys.stdin)['verify']['placements']:
    f = p['in_calibration_frame']['flush']
    print('  %-17s %6.2f mm %5.3f %5.3f deg' % (p['name'], f['height_rms'], f['roll_rms_deg'], f['pitch_rms_deg']))"
}
"$A" import-readings "$DATA/left_validation.csv" $U $L -o Lv.json 2>/dev/null >/dev/null
"$A" import-readings "$DATA/right_validation.csv" $U $R -o Rv.json 2>/dev/null >/dev/null
"$A" import-readings "$DATA/left_validation.csv" "$DATA/right_validation.csv" $U $B $VTIPS -o Bv.json 2>/dev/null >/dev/null
for prior in none 1,0.1 2,0.2 5,0.5 10,1; do
  P=""; [ "$prior" != none ] && P="--prior $prior"
  "$A" import-readings "$DATA/left_train.csv" $U $L $P -o L.json 2>/dev/null >/dev/null
  "$A" import-readings "$DATA/right_train.csv" $U $R $P -o R.json 2>/dev/null >/dev/null
  "$A" import-readings "$DATA/left_train.csv" "$DATA/right_train.csv" $U $B $TIPS $P -o B.json 2>/dev/null >/dev/null
  for s in L R B; do "$A" calibrate $s.json --write-machine ${s}cal.json > /dev/null 2>&1 || true; done
  echo "prior $prior, each hand alone:"
  figures Lv.json --machine Lcal.json --frame-of left_validation=left_train
  figures Rv.json --machine Rcal.json --frame-of right_validation=right_train
  echo "prior $prior, both hands:"
  figures Bv.json --machine Bcal.json --frame-of left_validation=left_train --frame-of right_validation=right_train
done
