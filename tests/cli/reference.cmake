# reference: bad input refused before the images are rendered.
set(ref_dir ${CMAKE_CURRENT_BINARY_DIR}/reference_fixtures)
file(WRITE ${ref_dir}/floor.obj "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n")
file(MAKE_DIRECTORY ${ref_dir}/folder.exr)
function(ref_scene name camera light)
  file(WRITE ${ref_dir}/${name}.json "{
  \"obj\": \"floor.obj\",
  \"camera\": { \"position\": [${camera}], \"look_at\": [0, 0, 0], \"up\": [0, 0, -1], \"fov_y_deg\": 60 },
  \"lights\": [ { \"type\": \"point\", \"position\": [${light}], \"intensity\": [1, 1, 1] } ],
  \"use_emission\": false
}
")
endfunction()
ref_scene(far_camera "0, 1e19, 0" "0, 1, 0")
ref_scene(far_light "0, 2, 0" "0, 1e19, 0")

set(ref_prog PROGRAM reference)
set(ref_small --width 8 --height 8 --spp 4 --no-cache --quiet)
bounce_cli_refusal("--json into /proc" ${ref_prog} MATCH "--json" ARGS ${ref_small} --out ${ref_dir}/r.exr --json /proc/x.json)
bounce_cli_refusal("--json /dev/full" ${ref_prog} MATCH "--json" ARGS ${ref_small} --out ${ref_dir}/r.exr --json /dev/full)
bounce_cli_refusal("--out with an unknown extension" ${ref_prog} MATCH "--out" ARGS ${ref_small} --out ${ref_dir}/r.unknown)
bounce_cli_refusal("--out a folder" ${ref_prog} MATCH "--out" ARGS ${ref_small} --out ${ref_dir}/folder.exr)
bounce_cli_refusal("--out into /proc" ${ref_prog} MATCH "--out" ARGS ${ref_small} --out /proc/r.exr)
bounce_cli_refusal("--png with an unknown extension" ${ref_prog} MATCH "--png" ARGS ${ref_small} --out ${ref_dir}/r.exr --png ${ref_dir}/r.unknown)
bounce_cli_refusal("--png /dev/full" ${ref_prog} MATCH "--png" ARGS ${ref_small} --out ${ref_dir}/r.exr --png /dev/full)
bounce_cli_refusal("an unwritable BOUNCE_CACHE" ${ref_prog} MATCH "BOUNCE_CACHE" ENV BOUNCE_CACHE=/proc/nocache ARGS --width 8 --height 8 --spp 4 --out ${ref_dir}/r.exr)
bounce_cli_refusal("--seed -1" ${ref_prog} MATCH "--seed" ARGS ${ref_small} --seed -1)
bounce_cli_refusal("--exposure nan" ${ref_prog} MATCH "--exposure" ARGS ${ref_small} --exposure nan)
bounce_cli_refusal("--environment nan" ${ref_prog} MATCH "--environment" ARGS ${ref_small} --environment nan 0 0)
bounce_cli_refusal("a camera at 1e19" ${ref_prog} MATCH "camera\\.position" ARGS ${ref_small} --scene ${ref_dir}/far_camera.json --out ${ref_dir}/r.exr)
bounce_cli_refusal("a light at 1e19" ${ref_prog} MATCH "lights.*position" ARGS ${ref_small} --scene ${ref_dir}/far_light.json --out ${ref_dir}/r.exr)
