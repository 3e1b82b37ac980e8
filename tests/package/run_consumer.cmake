file(REMOVE_RECURSE ${SCRATCH})
function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
endfunction()
run(${CMAKE_COMMAND} --install ${BOUNCE_BUILD_DIR} --prefix ${SCRATCH}/prefix)
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${SCRATCH}/build -G Ninja -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${SCRATCH}/prefix -DCONSUMER_WITH_VIEWS=${WITH_VIEWS} -DCONSUMER_WITH_VK=${WITH_VK}
    "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINKER_FLAGS}")
run(${CMAKE_COMMAND} --build ${SCRATCH}/build)
run(${SCRATCH}/build/consumer)
if(WITH_VK)
  run(${SCRATCH}/build/consumer_vk)
endif()
# The core alone: no component named, or only `core`; its configure step fails when any
# adapter's dependency was loaded.
run(${CMAKE_COMMAND} -S ${CORE_CONSUMER_SOURCE_DIR} -B ${SCRATCH}/core_build -G Ninja -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${SCRATCH}/prefix
    "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINKER_FLAGS}")
run(${CMAKE_COMMAND} --build ${SCRATCH}/core_build)
run(${SCRATCH}/core_build/core_consumer)
# The recipes of docs/embedding.md, each linked with the components its family needs, run on
# the renderer's own room (GL ones in a headless EGL context of bounce::gl's).
run(${CMAKE_COMMAND} -S ${EMBEDDING_SOURCE_DIR} -B ${SCRATCH}/embedding_build -G Ninja -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${SCRATCH}/prefix -DEMBEDDING_WITH_ADAPTERS=${WITH_ADAPTERS}
    "-DCMAKE_CXX_FLAGS=${CONSUMER_CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_LINKER_FLAGS}")
run(${CMAKE_COMMAND} --build ${SCRATCH}/embedding_build)
file(READ ${SCRATCH}/embedding_build/build.ninja ninja)
foreach(unwanted OpenImageIO tinyobjloader tinygltf bounce_io bounce_study)
  string(FIND "${ninja}" "${unwanted}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "the recipes' build mentions ${unwanted}: a renderer's own mesh needs no loader")
  endif()
endforeach()
set(recipes sh_core)
if(WITH_ADAPTERS)
  list(APPEND recipes cache_cpu splatter_gl rsm_cpu rsm_gl radiosity_cpu volume_cpu)
endif()
foreach(recipe IN LISTS recipes)
  run(${SCRATCH}/embedding_build/${recipe})
endforeach()
if(WITH_VIEWS)
  # The GL + Embree consumer links no OpenImageIO, tinyobjloader or tinygltf: nothing of bounce::io.
  file(READ ${SCRATCH}/build/build.ninja ninja)
  foreach(unwanted OpenImageIO tinyobjloader tinygltf bounce_io)
    string(FIND "${ninja}" "${unwanted}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "the gl + embree consumer's build mentions ${unwanted}")
    endif()
  endforeach()
  run(${SCRATCH}/build/consumer_views)
endif()
