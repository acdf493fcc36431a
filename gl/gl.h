// The one place gl/ includes the GL API: glad's GL 4.5 core loader (generated at build time).
// Only .cpp files of gl/ (and app code that talks GL directly) include this header.
#pragma once
#include <glad/gl.h>
