// The linear invocation index of a 1D compute pass that dispatch_compute_1d (gl/dispatch.h) laid
// out as a 2D grid of work groups: rows of at most GL_MAX_COMPUTE_WORK_GROUP_COUNT groups, so that
// a pass of any size fits the context's limits. The last row may run past the end: callers return
// for an index beyond their count.
// Include it after the layout(local_size_x = ...) declaration: gl_WorkGroupSize exists from there.
int flat_invocation() {
  uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  return int(group * gl_WorkGroupSize.x + gl_LocalInvocationID.x);
}
