# docs/embedding.md shows each recipe of tests/package/embedding/*.cpp: the lines between
# "// [recipe]" and "// [/recipe]", indented four spaces less, must appear in the doc as they
# are, so the doc cannot drift from the code the package test compiles and runs.
file(READ ${DOC} doc)
file(GLOB recipes ${RECIPE_DIR}/*.cpp)
list(LENGTH recipes count)
if(count EQUAL 0)
  message(FATAL_ERROR "no recipes in ${RECIPE_DIR}")
endif()
foreach(file IN LISTS recipes)
  file(READ ${file} text)
  string(FIND "${text}" "    // [recipe]\n" begin)
  string(FIND "${text}" "    // [/recipe]\n" end)
  if(begin EQUAL -1 OR end EQUAL -1 OR end LESS begin)
    message(FATAL_ERROR "${file}: no // [recipe] ... // [/recipe] region")
  endif()
  math(EXPR begin "${begin} + 16")
  math(EXPR length "${end} - ${begin}")
  string(SUBSTRING "${text}" ${begin} ${length} recipe)
  # A literal replacement after a leading newline: CMake's regex ^ would match again after
  # each replacement and strip nested indentation too.
  string(REPLACE "\n    " "\n" recipe "\n${recipe}")
  string(SUBSTRING "${recipe}" 1 -1 recipe)
  string(FIND "${doc}" "${recipe}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${DOC} does not show the recipe of ${file} as it is:\n${recipe}")
  endif()
endforeach()
message(STATUS "${count} recipes shown as they are in ${DOC}")
