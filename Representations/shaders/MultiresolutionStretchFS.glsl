//VTK::System::Dec
//VTK::Output::Dec
// Stretches the surface drawn at a reduced scale onto the view: the colour filtered, the depth
// of the nearest drawn texel written, so the view's other actors hide it and it them. Texels
// the surface did not cover (depth 1) leave the view as it was. The colour is normalised by
// its coverage, so silhouettes blend with the view, not with black.

in vec2 tcoordVC;
uniform sampler2D colorTexture;
uniform sampler2D depthTexture;
uniform vec2 drawnFraction; // the part of the textures drawn into
uniform vec2 halfTexel;

void main()
{
  vec2 at = tcoordVC * drawnFraction;
  float depth = texture(depthTexture, at).r;
  if (depth >= 1.0)
  {
    discard;
  }
  vec4 color = texture(colorTexture, clamp(at, halfTexel, drawnFraction - halfTexel));
  gl_FragData[0] = vec4(color.rgb / max(color.a, 1.0 / 255.0), 1.0);
  gl_FragDepth = depth;
}
