// The scene library's public headers: they compile for every library above it (the control of
// the probes that find a header missing).
#include "scene/auto_camera.h"
#include "scene/camera.h"
#include "scene/default_light.h"
#include "scene/load.h"
#include "scene/material.h"
#include "scene/range.h"
#include "scene/scene.h"
#include "scene/texture.h"
