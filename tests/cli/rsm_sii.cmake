# rsm_sii: bad input refused before the maps and references (issue 26, part 4). Every case
# asks for a 512x384 frame with 4096-ray references, which would take minutes, so a
# refusal that came after the work would miss the time limit.
set(rsm_big --width 512 --height 384 --ref-spp 4096)

bounce_cli_refusal("a --json in /proc" PROGRAM rsm_sii MATCH "--json"
                   ARGS ${rsm_big} --json /proc/rsm_sii_x.json)
bounce_cli_refusal("a --json that is a folder" PROGRAM rsm_sii MATCH "--json"
                   ARGS ${rsm_big} --json ${CMAKE_CURRENT_BINARY_DIR})
bounce_cli_refusal("an --out of an unknown image format" PROGRAM rsm_sii MATCH "--out"
                   ARGS ${rsm_big} --out rsm_sii_x.unknownformat)
bounce_cli_refusal("an --out that is a folder" PROGRAM rsm_sii MATCH "--out"
                   ARGS ${rsm_big} --out ${CMAKE_CURRENT_BINARY_DIR})
bounce_cli_refusal("an --indirect-out that is a folder" PROGRAM rsm_sii MATCH "--indirect-out"
                   ARGS ${rsm_big} --indirect-out ${CMAKE_CURRENT_BINARY_DIR})
bounce_cli_refusal("--out with --study (which wrote no image)" PROGRAM rsm_sii MATCH "--out/--indirect-out"
                   ARGS ${rsm_big} --study --json rsm_sii_study_x.json --out rsm_sii_x.png)
# More sub-buffers than lights gave a black image; the library's indirect_options refuses
# it naming both numbers, and the program names its flag.
bounce_cli_refusal("fewer VPLs than sub-buffers" PROGRAM rsm_sii
                   MATCH "--vpls.*16 VPLs are fewer than the 4096 sub-buffers of the 64x64"
                   ARGS ${rsm_big} --vpls 16 --pattern 64x64)
bounce_cli_refusal("fewer disc samples than sub-buffers" PROGRAM rsm_sii
                   MATCH "--vpls.*32 disc samples are fewer than the 64 sub-buffers of the 8x8"
                   ARGS ${rsm_big} --technique rsm --vpls 32 --pattern 8x8)
bounce_cli_refusal("an odd --ref-spp" PROGRAM rsm_sii MATCH "--ref-spp.*even"
                   ARGS --width 512 --height 384 --ref-spp 3)
bounce_cli_refusal("a --ref-spp of 2 (halves of one ray)" PROGRAM rsm_sii MATCH "--ref-spp.*even"
                   ARGS --width 512 --height 384 --ref-spp 2)
bounce_cli_refusal("a --clamp of nan" PROGRAM rsm_sii MATCH "--clamp.*'nan' is not a finite number >= 0"
                   ARGS ${rsm_big} --clamp nan)
bounce_cli_refusal("a negative --clamp" PROGRAM rsm_sii MATCH "--clamp"
                   ARGS ${rsm_big} --clamp -1)
bounce_cli_refusal("a --seed of -1" PROGRAM rsm_sii MATCH "--seed.*'-1' is not a whole number"
                   ARGS ${rsm_big} --seed -1)
bounce_cli_refusal("an --r-max of 0 (the bound is excluded)" PROGRAM rsm_sii MATCH "'0' is not a radius in .0, 2."
                   ARGS ${rsm_big} --r-max 0)
bounce_cli_refusal("--backend gl on a build without GL, or a bad backend" PROGRAM rsm_sii MATCH "--backend"
                   ARGS ${rsm_big} --backend vulkan)

# Scenes out of range: a closed box (2 units) with a point light, written here.
set(rsm_fx ${CMAKE_CURRENT_BINARY_DIR}/rsm_sii_fixtures)
set(rsm_box_v "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n")
set(rsm_box_f "f 1 2 3\nf 1 3 4\nf 5 8 7\nf 5 7 6\nf 1 5 6\nf 1 6 2\nf 1 4 8\nf 1 8 5\nf 2 6 7\nf 2 7 3\n")
file(WRITE ${rsm_fx}/box.obj "${rsm_box_v}${rsm_box_f}")
set(rsm_camera "\"camera\": {\"position\": [0, 1, 3.5], \"look_at\": [0, 1, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 45}")
# Intensities of 1e38 (float's range ends at 3.4e38): refused as the scene's, not as a
# parameter 'x' of something computed from them.
file(WRITE ${rsm_fx}/bright/scene.json "{ \"obj\": \"../box.obj\", ${rsm_camera},
  \"lights\": [{\"type\": \"point\", \"position\": [0, 1.8, 0], \"intensity\": [1e38, 1e38, 1e38]}] }\n")
bounce_cli_refusal("light intensities of 1e38" PROGRAM rsm_sii MATCH "lights\\[0\\]\\.intensity.*1e30"
                   ARGS ${rsm_big} --scene ${rsm_fx}/bright/scene.json)
# The box scaled by 1e19 (mesh, camera and light): the scene's coordinates are refused, not
# a --clamp derived from them that was never given.
file(WRITE ${rsm_fx}/huge/box.obj "v -1e19 0 -1e19\nv 1e19 0 -1e19\nv 1e19 0 1e19\nv -1e19 0 1e19\n"
           "v -1e19 2e19 -1e19\nv 1e19 2e19 -1e19\nv 1e19 2e19 1e19\nv -1e19 2e19 1e19\n${rsm_box_f}")
# (The camera and light stay within 1e18, inside the box, so the mesh is what is refused.)
file(WRITE ${rsm_fx}/huge/scene.json "{ \"obj\": \"box.obj\",
  \"camera\": {\"position\": [0, 5e17, 9e17], \"look_at\": [0, 5e17, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 45},
  \"lights\": [{\"type\": \"point\", \"position\": [0, 9e17, 0], \"intensity\": [1, 1, 1]}] }\n")
bounce_cli_refusal("a scene scaled by 1e19" PROGRAM rsm_sii MATCH "box\\.obj.*beyond \\+-1e18"
                   ARGS ${rsm_big} --scene ${rsm_fx}/huge/scene.json)
# The box as it is with its light at 1e19.
file(WRITE ${rsm_fx}/far_light/scene.json "{ \"obj\": \"../box.obj\", ${rsm_camera},
  \"lights\": [{\"type\": \"point\", \"position\": [0, 1e19, 0], \"intensity\": [1, 1, 1]}] }\n")
bounce_cli_refusal("a light at 1e19" PROGRAM rsm_sii MATCH "lights\\[0\\]\\.position.*1e18"
                   ARGS ${rsm_big} --scene ${rsm_fx}/far_light/scene.json)
# A scene without a light: nothing for a reflective shadow map to see.
file(WRITE ${rsm_fx}/dark/scene.json "{ \"obj\": \"../box.obj\", ${rsm_camera}, \"lights\": [] }\n")
bounce_cli_refusal("a scene without lights" PROGRAM rsm_sii MATCH "lights: empty.*no light"
                   ARGS ${rsm_big} --scene ${rsm_fx}/dark/scene.json)
