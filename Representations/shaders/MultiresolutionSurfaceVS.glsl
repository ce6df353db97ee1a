//VTK::System::Dec
#if __VERSION__ < 330 && !defined(GL_ES)
#extension GL_ARB_explicit_attrib_location : require
#endif
// Multiresolution surface, vertex stage (paper Sec. 5): positions relative to the model
// origin, and the cell coordinate (topological coordinate half a cell inside the face).
// The attributes' locations are fixed: every fragment shader variant links with this stage,
// and the meshes' vertex layouts, bound once, serve them all.

layout(location = 0) in vec3 vertexPosition;
layout(location = 1) in vec3 cellCoordinate;

uniform mat4 modelToClip;
uniform mat4 modelToView;

out vec3 cellCoord;
out vec3 viewPosition;
out float modelDepth; // depth below the origin: the wall depth table's frame
flat out float lastK; // a side triangle's largest k, from its last vertex (RegionCache)

void main()
{
  gl_Position = modelToClip * vec4(vertexPosition, 1.0);
  viewPosition = (modelToView * vec4(vertexPosition, 1.0)).xyz;
  cellCoord = cellCoordinate;
  modelDepth = -vertexPosition.z;
  lastK = cellCoordinate.z;
}
