// The GL passes' headers: they compile for the preview core.
#include "gl/blend_pass.h"
#include "gl/filter_pass.h"
#include "gl/range_pass.h"
