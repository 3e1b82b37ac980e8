# irradiance_volume: bad input refused before the bake and the references (issue 26, part 4).
# Every case asks for a depth-5 volume with 4096-sample references on the Cornell box, which
# takes minutes, so a refusal that came after the work would miss the time limit.
set(iv_big --max-depth 5 --ref-samples 4096)

bounce_cli_refusal("a --json of /dev/full" PROGRAM irradiance_volume MATCH "--json" ARGS ${iv_big} --json /dev/full)
bounce_cli_refusal("a --json in /proc" PROGRAM irradiance_volume MATCH "--json" ARGS ${iv_big} --json /proc/iv_x.json)
bounce_cli_refusal("an --out of an unknown image format" PROGRAM irradiance_volume MATCH "--out"
                   ARGS ${iv_big} --out iv_x.unknownformat)
bounce_cli_refusal("a depth whose grid exceeds memory" PROGRAM irradiance_volume
                   MATCH "--max-depth.*up to [0-9]+ probes, about [0-9.]+ [GT]B, more than the"
                   ARGS --max-depth 10)
bounce_cli_refusal("a --seed of -1" PROGRAM irradiance_volume MATCH "--seed.*'-1' is not a whole number"
                   ARGS ${iv_big} --seed -1)
foreach(option --radius --b --support --margin --gradient-step --distance-ratio --cull --prediction-tolerance --noise-sigmas --gradient-noise --self-shadow-bias --bias-budget --bias-tolerance)
  bounce_cli_refusal("${option} nan" PROGRAM irradiance_volume MATCH "${option}.*'nan' is not" ARGS ${iv_big} ${option} nan)
endforeach()
# --support must exceed 1; the refusal prints the open bound as such, "(1, 16]", not 1.000001
# (the brackets matched by '.': a bracket in a CMake list argument groups its semicolons).
bounce_cli_refusal("a --support of 1" PROGRAM irradiance_volume MATCH "--support.*'1' is not a support in .1, 16. "
                   ARGS ${iv_big} --support 1)
bounce_cli_refusal("a --path of nan" PROGRAM irradiance_volume MATCH "--path.*'nan' is not"
                   ARGS ${iv_big} --path 0.1 0.1 0.1 nan 0.5 0.5)
# Issue 31, third session: the sweep's budgets and the noise estimate's name.
bounce_cli_refusal("a --sweep-bias-budget of nan" PROGRAM irradiance_volume MATCH "--sweep-bias-budget.*'nan' is not"
                   ARGS ${iv_big} --sweep-bias-budget 1 nan)
bounce_cli_refusal("a --sweep-noise-sigmas of -1" PROGRAM irradiance_volume MATCH "--sweep-noise-sigmas.*'-1' is not"
                   ARGS ${iv_big} --sweep-noise-sigmas -1)
# Fourth session: the sweep's tolerances and depths.
bounce_cli_refusal("a --sweep-bias-tolerance of nan" PROGRAM irradiance_volume MATCH "--sweep-bias-tolerance.*'nan' is not"
                   ARGS ${iv_big} --sweep-bias-tolerance 0.1 nan)
bounce_cli_refusal("a --sweep-depths of 11" PROGRAM irradiance_volume MATCH "--sweep-depths.*11"
                   ARGS ${iv_big} --sweep-depths 4 11)
bounce_cli_refusal("a --noise-estimate not known" PROGRAM irradiance_volume MATCH "--noise-estimate.*thirds"
                   ARGS ${iv_big} --noise-estimate thirds)

# A closed box whose twelve triangles all face outwards (a room wound the wrong way), lit
# from inside: every probe's rays hit the backs of triangles, so every probe is inside and
# the volume would light nothing. The library says so instead of a black result.
set(iv_fx ${CMAKE_CURRENT_BINARY_DIR}/irradiance_volume_fixtures)
file(WRITE ${iv_fx}/reversed/box.obj "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\n"
  "f 1 2 3\nf 1 3 4\nf 5 8 7\nf 5 7 6\nf 1 5 6\nf 1 6 2\nf 1 4 8\nf 1 8 5\nf 2 6 7\nf 2 7 3\nf 4 3 7\nf 4 7 8\n")
file(WRITE ${iv_fx}/reversed/scene.json "{ \"obj\": \"box.obj\",
  \"camera\": {\"position\": [0, 1, 0.8], \"look_at\": [0, 1, -1], \"up\": [0, 1, 0], \"fov_y_deg\": 45},
  \"lights\": [{\"type\": \"point\", \"position\": [0, 1.8, 0], \"intensity\": [1, 1, 1]}] }\n")
bounce_cli_refusal("a scene whose triangles all face away" PROGRAM irradiance_volume MATCH "every one of the [0-9]+ probes is inside geometry"
                   ARGS --max-depth 2 --rays 64 --ref-samples 4096 --scene ${iv_fx}/reversed/scene.json)
bounce_cli_refusal("an unknown --interp" PROGRAM irradiance_volume MATCH "--interp: nearest not in .trilinear,weighted."
                   ARGS --interp nearest)
bounce_cli_refusal("an unknown --refit" PROGRAM irradiance_volume MATCH "--refit: maybe not in .on,off."
                   ARGS ${iv_big} --refit maybe)
bounce_cli_refusal("an unknown --refine" PROGRAM irradiance_volume MATCH "--refine: grow not in .merge,split."
                   ARGS ${iv_big} --refine grow)
bounce_cli_refusal("an unknown --conforming" PROGRAM irradiance_volume MATCH "--conforming: maybe not in .on,off."
                   ARGS ${iv_big} --conforming maybe)
bounce_cli_refusal("a --surface-size of 0" PROGRAM irradiance_volume MATCH "--surface-size.*0"
                   ARGS ${iv_big} --surface --surface-size 0)
bounce_cli_refusal("an unknown --relocate" PROGRAM irradiance_volume MATCH "--relocate: maybe not in .on,off."
                   ARGS ${iv_big} --relocate maybe)
