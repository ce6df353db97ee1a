//VTK::System::Dec
// Multiresolution surface, vertex stage (paper Sec. 5): positions relative to the model
// origin, and the cell coordinate (topological coordinate half a cell inside the face).

in vec3 vertexPosition;
in vec3 cellCoordinate;

uniform mat4 modelToClip;
uniform mat4 modelToView;

out vec3 cellCoord;
out vec3 viewPosition;

void main()
{
  gl_Position = modelToClip * vec4(vertexPosition, 1.0);
  viewPosition = (modelToView * vec4(vertexPosition, 1.0)).xyz;
  cellCoord = cellCoordinate;
}
