# radiosity: bad input refused before the work, with a message naming the cause (issue 26,
# part 4). Each case runs at most a few seconds; a refusal that came after the reference or
# the solve would miss the time or the message.

# Fixtures: a closed box whose faces are all wound outward (reversed) around a point light,
# and a 2 x 2 image (plain PPM, which OpenImageIO reads) to compare with a 16 x 16 view.
set(radiosity_fixtures ${CMAKE_CURRENT_BINARY_DIR}/radiosity_fixtures)
file(WRITE ${radiosity_fixtures}/reversed/box.obj
"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 3 2\nf 1 4 3\nf 5 7 8\nf 5 6 7\nf 1 6 5\nf 1 2 6\nf 4 7 3\nf 4 8 7\nf 1 8 4\nf 1 5 8\nf 2 7 6\nf 2 3 7\n")
file(WRITE ${radiosity_fixtures}/reversed/scene.json
"{ \"obj\": \"box.obj\", \"default_material\": { \"kd\": [0.7, 0.7, 0.7] },
  \"camera\": { \"position\": [0.5, 0.5, 0.9], \"look_at\": [0.5, 0.5, 0.0], \"up\": [0, 1, 0], \"fov_y_deg\": 60 },
  \"lights\": [ { \"type\": \"point\", \"position\": [0.5, 0.5, 0.5], \"intensity\": [1, 1, 1] } ],
  \"use_emission\": false }\n")
file(WRITE ${radiosity_fixtures}/two_by_two.ppm "P3\n2 2\n255\n0 0 0 255 255 255\n255 255 255 0 0 0\n")

set(quick --elements 300 --width 16 --height 16 --reference-paths 4)

bounce_cli_refusal("an unwritable BOUNCE_CACHE before the reference" PROGRAM radiosity
  MATCH "BOUNCE_CACHE" SECONDS 10 ENV BOUNCE_CACHE=/proc/nocache ARGS ${quick})
bounce_cli_refusal("a --versus file that does not exist, before the solve" PROGRAM radiosity
  MATCH "--versus.*no such file" SECONDS 10 ARGS ${quick} --versus ${radiosity_fixtures}/missing.exr)
bounce_cli_refusal("a --versus image of another size, before the solve" PROGRAM radiosity
  MATCH "--versus.*2 x 2, not the 16 x 16" SECONDS 10 ARGS ${quick} --versus ${radiosity_fixtures}/two_by_two.ppm)
bounce_cli_refusal("a --tolerance-px no item buffer can resolve, with the floor" PROGRAM radiosity
  MATCH "--tolerance-px.*below 0.003906 px" SECONDS 10 ARGS ${quick} --tolerance-px 1e-7)
bounce_cli_refusal("a negative --seed" PROGRAM radiosity MATCH "--seed" SECONDS 10 ARGS ${quick} --seed -1)
bounce_cli_refusal("a NaN --converge" PROGRAM radiosity MATCH "--converge" SECONDS 10 ARGS ${quick} --converge nan)
bounce_cli_refusal("a NaN --near-field" PROGRAM radiosity MATCH "--near-field" SECONDS 10 ARGS ${quick} --near-field nan)
bounce_cli_refusal("grouped shooters with an item buffer (they cast rays from the members)" PROGRAM radiosity
  MATCH "--shooter-groups.*--visibility rays" SECONDS 10 ARGS ${quick} --shooter-groups 64 --visibility stereo)
bounce_cli_refusal("a NaN --max-seconds" PROGRAM radiosity MATCH "--max-seconds" SECONDS 10 ARGS ${quick} --max-seconds nan)
bounce_cli_refusal("an --out of an unknown image type" PROGRAM radiosity
  MATCH "--out.*\\.png or \\.exr" SECONDS 10 ARGS ${quick} --out ${CMAKE_CURRENT_BINARY_DIR}/r.unknown)
bounce_cli_refusal("an --out that is a folder" PROGRAM radiosity
  MATCH "--out" SECONDS 10 ARGS ${quick} --out ${CMAKE_CURRENT_BINARY_DIR}/radiosity_fixtures.exr/)
bounce_cli_refusal("a --json under /proc" PROGRAM radiosity MATCH "--json" SECONDS 10 ARGS ${quick} --json /proc/r.json)
bounce_cli_refusal("a scene whose triangles all face away from its light (reversed winding), one-sided" PROGRAM radiosity
  MATCH "reversed winding" SECONDS 10 ARGS ${quick} --one-sided --scene ${radiosity_fixtures}/reversed/scene.json)

# 50 million elements under a 4 GB address-space limit (prlimit): refused with the estimate
# before anything is allocated, not std::bad_alloc or the OOM killer. Not under
# AddressSanitizer: it reserves terabytes of shadow address space at start, which the limit
# forbids before the program runs a line.
find_program(PRLIMIT prlimit)
if(TARGET radiosity AND PRLIMIT AND NOT CMAKE_CXX_FLAGS MATCHES "sanitize=address")
  set(name "radiosity refuses: 50 million elements under a 4 GB memory limit, with the estimate")
  add_test(NAME "${name}"
           COMMAND ${CMAKE_COMMAND} "-DPROGRAM=${PRLIMIT}" "-DMATCH=--elements.*GiB" "-DSECONDS=10"
                   "-DWORKDIR=${CMAKE_CURRENT_BINARY_DIR}"
                   "-DARGS=--as=4000000000;$<TARGET_FILE:radiosity>;--elements;50000000;--reference;off"
                   -P ${CMAKE_CURRENT_SOURCE_DIR}/run_refusal.cmake)
  set_tests_properties("${name}" PROPERTIES LABELS default TIMEOUT 60
                       ENVIRONMENT "BOUNCE_SCENES=${BOUNCE_TEST_SCENES};BOUNCE_CACHE=${CMAKE_CURRENT_BINARY_DIR}/cache")
endif()

# Named choices are read into enums at parse time: an unknown name is refused there, listing
# the names (examples/common/cli_choices.hpp).
bounce_cli_refusal("an unknown --backend" PROGRAM radiosity MATCH "--backend: vulkan not in .cpu,gl."
  SECONDS 10 ARGS ${quick} --backend vulkan)
# The GL solver is two-sided by default as the CPU solver is (issue 30): one-sided, the box wound
# outward around its light is refused naming the winding; two-sided, it is solved and seen
# through the direct+indirect view, with the oracle's split written (the view and the oracle
# run on the lightmaps read back from GL).
if(BOUNCE_WITH_GL AND TARGET radiosity)
  bounce_cli_refusal("a scene whose triangles all face away from its light, one-sided on the GL backend"
    PROGRAM radiosity MATCH "reversed winding" SECONDS 10
    ARGS ${quick} --backend gl --one-sided --scene ${radiosity_fixtures}/reversed/scene.json)
  set(name "radiosity on GL lights a box wound outward two-sided, direct+indirect view and --oracle-out")
  add_test(NAME "${name}"
           COMMAND radiosity ${quick} --backend gl --view direct+indirect --quiet --scene ${radiosity_fixtures}/reversed/scene.json
                   --json ${CMAKE_CURRENT_BINARY_DIR}/radiosity_gl/r.json --oracle-out ${CMAKE_CURRENT_BINARY_DIR}/radiosity_gl/oracle.json)
  set_tests_properties("${name}" PROPERTIES LABELS default TIMEOUT 120 PASS_REGULAR_EXPRESSION "rel_rms [0-9.]+, 0 black pixels"
                       ENVIRONMENT "BOUNCE_SCENES=${BOUNCE_TEST_SCENES};BOUNCE_CACHE=${CMAKE_CURRENT_BINARY_DIR}/cache")
endif()
bounce_cli_refusal("an unknown --visibility" PROGRAM radiosity MATCH "--visibility: raster not in .stereo,hemicube,rays."
  SECONDS 10 ARGS ${quick} --visibility raster)
