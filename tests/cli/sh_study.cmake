# sh_study: outputs checked before the work, memory estimated before allocating (issue 26,
# part 4). The default run projects 1000 maps and takes seconds; 100000 maps of 1024^2
# texels would need terabytes, so a refusal that came late would crash or time out.
bounce_cli_refusal("a --json in /proc" PROGRAM sh_study MATCH "--json" ARGS --json /proc/sh_study_x.json)
bounce_cli_refusal("a --json of /dev/full" PROGRAM sh_study MATCH "--json" ARGS --json /dev/full)
bounce_cli_refusal("a --json that is a folder" PROGRAM sh_study MATCH "--json" ARGS --json ${CMAKE_CURRENT_BINARY_DIR})
bounce_cli_refusal("100000 maps of 1024^2 texels" PROGRAM sh_study MATCH "maps.*need [0-9.e+]+ [GT]B, more than the"
                   ARGS --maps 100000 --size 1024)
bounce_cli_refusal("--maps nan" PROGRAM sh_study MATCH "--maps" ARGS --maps nan)
bounce_cli_refusal("--size -1" PROGRAM sh_study MATCH "--size" ARGS --size -1)

# A --json into a folder that does not exist yet: the folder is made and the file written.
if(TARGET sh_study)
  set(sh_study_new ${CMAKE_CURRENT_BINARY_DIR}/sh_study_new_folder)
  add_test(NAME "sh_study writes --json into a new folder"
           COMMAND sh -c "rm -rf '${sh_study_new}' && '$<TARGET_FILE:sh_study>' --maps 2 --size 8 --repeat 1 --json '${sh_study_new}/a/b.json' > /dev/null && grep -q '\"provenance\"' '${sh_study_new}/a/b.json'")
  set_tests_properties("sh_study writes --json into a new folder" PROPERTIES LABELS default TIMEOUT 120)
endif()
