// tinyobjloader's implementation, compiled into the fuzzer so that its parser carries
// coverage instrumentation and sanitizer checks (the shared library does not).
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
