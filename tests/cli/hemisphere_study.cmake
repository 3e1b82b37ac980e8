# hemisphere_study: bad input refused before the reference and the samplers run.
set(hs_dir ${CMAKE_CURRENT_BINARY_DIR}/hemisphere_study_fixtures)
# A lit floor under a camera, then the same with the camera, the light or a vertex beyond
# the +-1e18 that float32 rays carry (the core's max_world_coordinate).
file(WRITE ${hs_dir}/floor.obj "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 3 2\nf 1 4 3\n")
file(WRITE ${hs_dir}/far_vertex.obj "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1e30\nf 1 3 2\nf 1 4 3\n")
function(hs_scene name obj camera light)
  file(WRITE ${hs_dir}/${name}.json "{
  \"obj\": \"${obj}\",
  \"camera\": { \"position\": [${camera}], \"look_at\": [0, 0, 0], \"up\": [0, 0, -1], \"fov_y_deg\": 60 },
  \"lights\": [ { \"type\": \"point\", \"position\": [${light}], \"intensity\": [1, 1, 1] } ],
  \"use_emission\": false
}
")
endfunction()
hs_scene(far_camera floor.obj "0, 1e19, 0" "0, 1, 0")
hs_scene(far_light floor.obj "0, 2, 0" "0, 1e19, 0")
hs_scene(far_vertex far_vertex.obj "0, 2, 0" "0, 1, 0")

set(hs PROGRAM hemisphere_study)
bounce_cli_refusal("--json into /proc" ${hs} MATCH "--json" ARGS --scene cornell --json /proc/x.json)
bounce_cli_refusal("--json /dev/full" ${hs} MATCH "--json" ARGS --scene cornell --json /dev/full)
bounce_cli_refusal("--json into a missing folder under /proc" ${hs} MATCH "--json" ARGS --scene cornell --json /proc/no/x.json)
bounce_cli_refusal("--points-csv /dev/full" ${hs} MATCH "--points-csv" ARGS --scene cornell --points-csv /dev/full)
bounce_cli_refusal("an unwritable BOUNCE_CACHE" ${hs} MATCH "BOUNCE_CACHE" ENV BOUNCE_CACHE=/proc/nocache ARGS --scene cornell --points 10)
bounce_cli_refusal("an unwritable --cache-dir" ${hs} MATCH "cache" ARGS --scene cornell --points 10 --cache-dir /proc/nocache)
bounce_cli_refusal("--seed -1" ${hs} MATCH "--seed" ARGS --scene cornell --seed -1)
bounce_cli_refusal("--aperture nan" ${hs} MATCH "--aperture" ARGS --scene cornell --aperture nan)
bounce_cli_refusal("--reference-target nan" ${hs} MATCH "--reference-target" ARGS --scene cornell --reference-target nan)
bounce_cli_refusal("--shadow-normal-offset nan" ${hs} MATCH "--shadow-normal-offset" ARGS --scene cornell --shadow-normal-offset nan)
bounce_cli_refusal("--plane-turn nan" ${hs} MATCH "--plane-turn" ARGS --scene cornell --plane-turn nan)
bounce_cli_refusal("a camera at 1e19" ${hs} MATCH "camera\\.position" ARGS --scene ${hs_dir}/far_camera.json --points 10 --no-cache)
bounce_cli_refusal("a light at 1e19" ${hs} MATCH "lights.*position" ARGS --scene ${hs_dir}/far_light.json --points 10 --no-cache)
bounce_cli_refusal("a vertex at 1e30" ${hs} MATCH "1e18|positions" ARGS --scene ${hs_dir}/far_vertex.json --points 10 --no-cache)
