// A glTF reader, private to the scene library: no library above it finds this header.
#include "scene/gltf_accessor.h"
