#!/usr/bin/env bash
# The lead detector's training and export at a tiny size (what CI runs): render one small unmarked
# dataset, train a narrow network for a few steps, export it, and score it with `wingman bench-lead`
# (OpenCV's dnn must load what PyTorch wrote).   tools/test_lead_training.sh WINGMAN WORKDIR
set -euo pipefail
wingman=$1
work=$2
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
rm -rf "$work"
mkdir -p "$work"
python3 "$here/tools/lead_data.py" --wingman "$wingman" --out "$work/data" --grounds freetown,site --leads truck \
  --per-pair 1 --duration 1 --rate 2
/usr/bin/python3 "$here/tools/train_lead_detector.py" --data "$work/data" --hold-out site --out "$work/tiny.onnx" \
  --epochs 2 --steps-per-epoch 3 --batch 4 --width 8 --threads 1
test -s "$work/tiny.onnx" && test -s "$work/tiny.json"
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); assert r['training']['epochs']==2 and r['export']['opset']==11, r" \
  "$work/tiny.json"
"$wingman" bench-lead "$work"/data/site_truck_1_0 --weights "$work/tiny.onnx" --threshold 0.5 --quiet
echo "test_lead_training: trained, exported and scored"
