#!/usr/bin/env bash
# The pictures of docs/rendering.md, "Shutter and sensor": the frame at 1.5 s (auto-exposure has
# settled by then) of a camera 15 m above the paper world flying at 12 m/s, rendered ideal and with
# each camera effect alone and all together, each cropped to the same 200 px square and enlarged 2x:
#   tools/camera_effects_pictures.sh WINGMAN OUT.png
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ $# -eq 2 ] || { sed -n 2,5p "$0"; exit 2; }
wingman=$(realpath "$1"); out=$2
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
g++ -O2 -std=c++17 "$here/tools/frames_to_png.cpp" -o "$work/frames_to_png" $(pkg-config --cflags --libs opencv4)
declare -A effect=(
  [ideal]=""
  [exposure]="shutter: {exposure: 0.02, subframes: 15}"
  [rolling]="shutter: {type: rolling, line_delay: 5.0e-5}"
  [sensor]="sensor: {model: physical, full_well: 2000, read_noise: 8, prnu: 0.02, dsnu: 4, vignetting: 1,
                      auto_exposure: {enabled: true, target: 0.3, max_exposure: 0.001, max_gain: 16}}"
  [all]="shutter: {type: rolling, line_delay: 5.0e-5, subframes: 15},
              sensor: {model: physical, full_well: 2000, read_noise: 8, prnu: 0.02, dsnu: 4, vignetting: 1,
                       auto_exposure: {enabled: true, target: 0.3, max_exposure: 0.02, max_gain: 16}}"
)
tiles=()
for name in ideal exposure rolling sensor all; do
  extra=${effect[$name]}
  cat > "$work/$name.yaml" <<YAML
name: effects_$name
duration: 2
rate: 10
measurements: rendered
lead: {initial_position: [0, 0, 0], trajectory: {type: line, velocity: [12, 0, 0]}}
uavs:
  - name: uav1
    initial_position: [0, 0, 15]
    camera: {fx: 200.1, fy: 200.1, cx: 500, cy: 500, width: 1000, height: 1000${extra:+,
             $extra}}
world: {image: {msaa: 1}, texture: {anisotropy: 1}}
YAML
  "$wingman" render "$work/$name.yaml" --frames 16 --rgb --gl auto -q --out "$work/$name"
  tiles+=("$work/$name/uav1/mav0/cam0/data/1500000000.png@560,330,200")
done
"$work/frames_to_png" "$out" 400 "${tiles[@]}"
echo "wrote $out"
