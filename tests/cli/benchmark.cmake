# benchmark: bad options refused before any reference or technique runs.
set(bm PROGRAM benchmark)
bounce_cli_refusal("an unknown technique" ${bm} MATCH "unknown technique 'pathtracing'"
  ARGS --quick --techniques irradiance_cache,pathtracing --json bm.json)
bounce_cli_refusal("an unknown scene, naming the path tried" ${bm} MATCH "/nowhere/atlantis/scene.json"
  ENV BOUNCE_SCENES=/nowhere ARGS --scenes cornell,atlantis --json bm.json)
bounce_cli_refusal("--json into /proc" ${bm} MATCH "--json" ARGS --quick --json /proc/x.json)
bounce_cli_refusal("--json /dev/full" ${bm} MATCH "--json" ARGS --quick --json /dev/full)
bounce_cli_refusal("--width 0" ${bm} MATCH "--width" ARGS --quick --width 0 --json bm.json)
bounce_cli_refusal("--height 0" ${bm} MATCH "--height" ARGS --quick --height 0 --json bm.json)
bounce_cli_refusal("an unwritable BOUNCE_CACHE" ${bm} MATCH "BOUNCE_CACHE" ENV BOUNCE_CACHE=/proc/nocache
  ARGS --quick --json bm.json)
