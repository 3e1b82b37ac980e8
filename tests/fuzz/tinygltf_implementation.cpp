// tinygltf's implementation, compiled into the fuzz targets with coverage and sanitizers
// (the io library links Debian's libtinygltf instead). Debian ships no stb headers, so
// this build decodes no images: TINYGLTF_NO_STB_IMAGE is defined for the whole target, and
// a base-colour texture raises scene_error there.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
