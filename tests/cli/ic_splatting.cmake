# ic_splatting refuses bad input before any work (issue 26, part 4): each case would otherwise
# run for seconds to minutes (a reference, records) and fail late, wrap, or abort in Embree.

# Outputs: an unknown image format, a folder, a file that cannot be created, a device.
bounce_cli_refusal(out-unknown-extension PROGRAM ic_splatting
  MATCH "--out.*'\\.unknown' is not an image format" ARGS --out result.unknown)
bounce_cli_refusal(out-folder PROGRAM ic_splatting
  MATCH "--out.*is a folder" ARGS --out ${CMAKE_CURRENT_BINARY_DIR})
bounce_cli_refusal(indirect-exr-unknown-extension PROGRAM ic_splatting
  MATCH "--indirect-exr.*'\\.txt' is not an image format" ARGS --indirect-exr indirect.txt)
bounce_cli_refusal(json-proc PROGRAM ic_splatting
  MATCH "--json.*/proc/ic.json" ARGS --json /proc/ic.json)
bounce_cli_refusal(json-dev-full PROGRAM ic_splatting
  MATCH "--json.*/dev/full" ARGS --json /dev/full)
bounce_cli_refusal(cache-out-dev-full PROGRAM ic_splatting
  MATCH "--cache-out.*/dev/full" ARGS --cache-out /dev/full)
bounce_cli_refusal(cache-in-missing PROGRAM ic_splatting
  MATCH "--cache-in.*missing" ARGS --cache-in ${CMAKE_CURRENT_BINARY_DIR}/no-such.cache)
# The reference cache must be writable before the reference is computed.
bounce_cli_refusal(reference-cache-proc PROGRAM ic_splatting
  MATCH "BOUNCE_CACHE" ENV BOUNCE_CACHE=/proc/nocache ARGS --width 16 --height 16)

# A camera or a light beyond what float32 rays carry: refused naming the field, not an
# Embree assertion (exit 134).
set(ic_far ${CMAKE_CURRENT_BINARY_DIR}/ic_splatting_far)
file(WRITE ${ic_far}/box.obj "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -1 2 -1\nv 1 2 -1\nf 1 3 2\nf 1 4 3\nf 1 2 6\nf 1 6 5\n")
set(ic_material "\"default_material\": { \"kd\": [0.8, 0.8, 0.8] }")
file(WRITE ${ic_far}/far_camera.json "{ \"obj\": \"box.obj\", ${ic_material},
  \"camera\": { \"position\": [0.0, 1.0, 1e19], \"look_at\": [0.0, 1.0, 0.0], \"up\": [0, 1, 0], \"fov_y_deg\": 40.0 },
  \"lights\": [ { \"type\": \"point\", \"position\": [0.0, 1.5, 0.5], \"intensity\": [1.0, 1.0, 1.0] } ] }\n")
file(WRITE ${ic_far}/far_light.json "{ \"obj\": \"box.obj\", ${ic_material},
  \"camera\": { \"position\": [0.0, 1.0, 4.0], \"look_at\": [0.0, 1.0, 0.0], \"up\": [0, 1, 0], \"fov_y_deg\": 40.0 },
  \"lights\": [ { \"type\": \"point\", \"position\": [0.0, 1e19, 0.5], \"intensity\": [1.0, 1.0, 1.0] } ] }\n")
bounce_cli_refusal(camera-at-1e19 PROGRAM ic_splatting
  MATCH "camera\\.position.*1e18" ARGS --scene ${ic_far}/far_camera.json --width 16 --height 16 --ref-spp 16)
bounce_cli_refusal(light-at-1e19 PROGRAM ic_splatting
  MATCH "lights\\[0\\]\\.position.*1e18" ARGS --scene ${ic_far}/far_light.json --width 16 --height 16 --ref-spp 16)

# A scene name looked for under BOUNCE_SCENES names the path it tried.
bounce_cli_refusal(scene-not-under-scenes PROGRAM ic_splatting
  MATCH "/nowhere/sponza" ENV BOUNCE_SCENES=/nowhere ARGS --scene sponza)

# Negative counts: CLI11 reads "-1" into an unsigned option as its largest value (a
# walkthrough of 2^64 frames). ic_splatting has no --seed; the case keeps it that way or
# refused.
bounce_cli_refusal(seed-negative PROGRAM ic_splatting MATCH "--seed" ARGS --seed -1)
foreach(count walkthrough progressive walkthrough-mc-stride frames)
  bounce_cli_refusal(${count}-negative PROGRAM ic_splatting
    MATCH "--${count}.*-1" ARGS --${count} -1)
endforeach()

# NaN in every number option (CLI11's own Range and PositiveNumber let it through).
foreach(option a falloff-kappa plane-turn fill-holes record-error record-error-floor min-pixels max-pixels
               max-extrapolation front-tolerance min-weight a-sweep frames record-samples ref-spp width repeat
               scan-batch shadow-resolution min-record-samples mc-max-spp ambient-resolution max-world-ratio
               min-mean-distance hessian-zone-cap importance-defensive)
  bounce_cli_refusal(${option}-nan PROGRAM ic_splatting MATCH "--${option}.*nan" ARGS --${option} nan)
endforeach()

# Importance-sampled records: a fixed budget, so not with the adaptive rays' target, and a
# first round within it.
bounce_cli_refusal(importance-with-adaptive PROGRAM ic_splatting
  MATCH "--importance-rays.*not with --adaptive-rays" ARGS --importance-rays --adaptive-rays)
bounce_cli_refusal(importance-first-round PROGRAM ic_splatting
  MATCH "--min-record-samples.*must not exceed --record-samples" ARGS --importance-rays --min-record-samples 2048)

# World limits: the ratio of the largest radius to the smallest is at least 1, and the
# Hessian's zone cap means nothing to the split sphere.
bounce_cli_refusal(max-world-ratio-below-one PROGRAM ic_splatting MATCH "--max-world-ratio" ARGS --max-world-ratio 0.5)
bounce_cli_refusal(hessian-zone-cap-split-sphere PROGRAM ic_splatting
  MATCH "--hessian-zone-cap.*applies to --radius hessian only" ARGS --hessian-zone-cap 1)

# Named choices are read into enums at parse time: an unknown name (or an enum's number) is
# refused there, listing the names (examples/common/cli_choices.hpp).
bounce_cli_refusal(interp-unknown PROGRAM ic_splatting
  MATCH "--interp: splat-vulkan not in .splat-cpu,splat-gl,octree,octree-lanes." ARGS --interp splat-vulkan)
bounce_cli_refusal(sampler-number PROGRAM ic_splatting MATCH "--sampler: 1 not in .embree,raster." ARGS --sampler 1)

# The verification pass runs in both splat frames (CPU and GL), not with the octree.
bounce_cli_refusal(verify-octree PROGRAM ic_splatting
  MATCH "--verify.*splat-cpu or splat-gl" ARGS --verify 2 --interp octree)
