//VTK::System::Dec
//VTK::Output::Dec
// Multiresolution surface, fragment stage (paper Sec. 5.1-5.4): the original cell under the
// fragment is floor(cell coordinate); its property and top/bottom normal are found through
// the perfect spatial hash (two texel fetches); the original grid lines are where the
// coordinate crosses an integer, drawn a fixed width in pixels and faded out where cells
// shrink below a few pixels. In the single-layer view (layer >= 0) the property comes from
// that layer's 2D table, indexed by (i, j) without the hash; the cells an I/J/K range's cuts
// expose (inside the model, not in the hash) from the planes of cells along each cut; the
// faces a property filter exposes from the values their region's triangles carry.
//
// Lit as VTK lights its surfaces (ours: the renderer's lights and the actor's material, so
// the surface looks as ParaView's Surface of the full grid): a property's colour is both the
// ambient and the diffuse colour, as on stock surfaces coloured by an array, and each of the
// renderer's lights adds a diffuse and a specular term.
//
// The mapper compiles one variant per painting mode, with these defined (0 or 1):
// COLOR_MODE (0: solid colour, 1: property, 2: cell id, 3: the pick pass's cell (i, j, k)), LAYER_VIEW (one layer drawn),
// LOG_SCALE, GRID_LINES, SPECULAR, TABLE_NORMALS (tops and bottoms lit by the normal
// table), WALL_DEPTHS (side fragments find their layer from their depth, below), CELL_FILTER
// (an I/J/K range or a property filter: cut planes and face values), and LIGHTING (0: unlit,
// 1: headlight, 2: directional lights, 3: positional lights, as vtkOpenGLRenderer's lighting
// complexity), with the
// renderer's light uniforms declared and one call a light generated at //RESMR::Lights.
// A software rasterizer (llvmpipe) runs both sides of every branch on a uniform, masked;
// compiled out, the unused paths cost nothing (a tenth of a full-screen frame there), and
// GPUs keep fewer registers.

in vec3 cellCoord;
in vec3 viewPosition;
flat in float lastK; // a side triangle's largest k

uniform int faceKind;     // 0: top, 1: bottom, 2: side
uniform int sideOneLayer; // on sides, 1: each triangle spans one layer (the exact side)
uniform ivec3 gridDims;   // nx, ny, nz
uniform ivec3 cellLow;    // the lowest cell drawn: 0, or an I/J/K range's
uniform ivec3 cellHigh;   // the highest: gridDims - 1, or a range's
uniform ivec3 cutLow;     // an I/J/K range's lowest cells where it cuts the grid, -1: no cut
uniform ivec3 cutHigh;    // its highest cells where it cuts the grid, -1: no cut
uniform sampler2D cutLowK;  // nx x ny, R32F: the values of the range's K low plane
uniform sampler2D cutHighK; // nx x ny, R32F: of its K high plane
uniform sampler2D cutSides; // max(nx, ny) x 4 nz, R32F: of its I low, I high, J low, J high planes
uniform int cutReady;       // bit p: plane p (K low, K high, I low, ..., J high) is loaded
uniform int faceValuesOn;   // 1: the region's faces carry their cells' values (a property filter)
uniform samplerBuffer faceValues; // one value a triangle of the region
uniform int primitiveBase;  // the region's triangle number of this draw's first
uniform ivec3 tableSides; // m
uniform ivec3 offsetSides; // r
uniform usampler3D hashOffsets;  // r0 x r1 x r2, RGB16UI
uniform usampler3D cellNormals;  // m0 x m1 x m2, RG16UI (top, bottom)
uniform sampler3D propertyTable; // m0 x m1 x m2, R32F
uniform int layer;               // -1: the whole model; else the one layer drawn (0-based)
uniform sampler2D layerProperty; // nx x ny, R32F: that layer's table
uniform sampler2D colorMap;      // N x 1, RGBA8
uniform vec2 scalarRange;        // lookup table range (log10 of it with LOG_SCALE)
uniform vec4 nanColor;
uniform vec3 solidColor;
uniform float gridLineWidth;     // pixels of the view
uniform float renderScale;       // pixels drawn per pixel of the view, a side (1: full)
uniform vec3 gridLineColor;
uniform vec3 ambientColorUniform;  // the actor's ambient colour times its Ambient
uniform float ambientIntensity;
uniform float diffuseIntensity;
uniform vec3 specularColorUniform; // the actor's specular colour times its Specular
uniform float specularPower;
uniform mat3 normalToView;
uniform int cameraParallel;        // 1: parallel projection (the eye looks along -z everywhere)
//RESMR::LightUniforms

// a mod m for 0 <= a < 2^24: the quotient in float, corrected by one either way (a divide
// may be a reciprocal and a multiply). Integer division has no vector instruction on CPUs
// (llvmpipe runs it lane by lane) and is slow on GPUs too.
ivec3 Modulo(ivec3 a, ivec3 m)
{
  ivec3 r = a - m * ivec3(floor(vec3(a) / vec3(m)));
  r += m * ivec3(lessThan(r, ivec3(0)));
  return r - m * ivec3(greaterThanEqual(r, m));
}

ivec3 HashSlot(ivec3 cell)
{
  ivec3 offset = ivec3(texelFetch(hashOffsets, Modulo(cell, offsetSides), 0).xyz);
  ivec3 slot = Modulo(cell, tableSides) + offset; // offsets are below the sides
  return slot - tableSides * ivec3(greaterThanEqual(slot, tableSides));
}

vec3 DecodeNormal(uint code)
{
  // Two signed bytes (GLSL 1.50 has no bitfieldExtract).
  ivec2 bytes = ivec2(int(code & 255u), int((code >> 8u) & 255u));
  bytes -= ivec2(greaterThanEqual(bytes, ivec2(128))) * 256;
  vec2 e = max(vec2(bytes) / 127.0, vec2(-1.0));
  vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
  float t = max(-n.z, 0.0);
  n.xy -= t * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  return normalize(n);
}

#if WALL_DEPTHS
// Wall depths (ours, WallDepthTable.h): a coarse wall paints each cell within its error of its
// place, many layers on a many-layer model; the wall's true interfaces at the fragment's place
// along the face give its layer exactly. Faces are hashed by (i, j, face) as cells are.
in float modelDepth;             // depth below the origin, as the table's
uniform usampler3D wallOffsets;  // the wall hash's offsets, RGB16UI
uniform usampler3D wallKeys;     // rows x slabs, RG32UI a slot: key (j nx + i) 4 + face + 1, row
uniform sampler3D wallDepths;    // (nk + 1) x rows x slabs, RGB32F a face: depth at A, at B, open cell
uniform ivec3 wallTableSides;
uniform ivec3 wallOffsetSides;
uniform int wallRows;            // slots a slab of wallKeys
uniform int wallFaceRows;        // faces a slab of wallDepths
uniform int wallSearchSteps;     // 2^steps >= nk
uniform int wallSideSign;        // the topology's handedness, negated when glFrontFace is GL_CW
uniform int wallLookup;          // 0: the region's sides are the original faces (a leaf)

// n as (n mod rows, n / rows), a texel of a table laid out in slabs of `rows`.
ivec2 InSlabs(int n, int rows)
{
  int row = Modulo(ivec3(n), ivec3(rows)).x;
  return ivec2(row, int(round(float(n - row) / float(rows))));
}

// The face's slot: its key, and its row of the depth table.
uvec2 WallSlot(ivec3 face)
{
  ivec3 offset = ivec3(texelFetch(wallOffsets, Modulo(face, wallOffsetSides), 0).xyz);
  ivec3 h = Modulo(face, wallTableSides) + offset;
  h -= wallTableSides * ivec3(greaterThanEqual(h, wallTableSides));
  int slot = h.x + wallTableSides.x * (h.y + wallTableSides.y * h.z);
  return texelFetch(wallKeys, ivec3(InSlabs(slot, wallRows), 0), 0).rg;
}

float WallDepthAt(ivec2 faceAt, int k, float along)
{
  vec2 d = texelFetch(wallDepths, ivec3(k, faceAt), 0).xy;
  return mix(d.x, d.y, along);
}

// A side fragment's cell on the wall it lies on: the layer is the interpolated one when the
// fragment lies within half a pixel of its interfaces (always at the finest level), else the
// one whose interfaces hold its depth, then the nearest cell the exact wall shows. False off
// the table's faces (a triangle nearer level in (i, j, k) than upright, or whose coordinates
// name no column with a wall nearby); else `lines`: pixels to the nearer interface and the
// layer's thickness in pixels.
bool WallCell(inout ivec3 cell, vec3 topoNormal, float depthPerPixel, out vec2 lines)
{
  lines = vec2(0.0);
  vec3 size = abs(topoNormal);
  if (size.z >= max(size.x, size.y))
  {
    return false;
  }
  // The face: the first the table holds of the column's faces on the constant axis of the
  // fragment's coordinates, then on the other (a coarse wall running slanted in (i, j) over a
  // staircase outline). First the one the triangle's turn names: its topological normal is
  // the cross product of the coordinate's screen derivatives, signed by the turn on the
  // screen, and the cell lies against it times the handedness (RegionCache's offsets).
  int axis = size.x >= size.y ? 0 : 1;
  float normal = (axis == 0 ? topoNormal.x : topoNormal.y) * (gl_FrontFacing ? 1.0 : -1.0);
  int upper = -float(wallSideSign) * normal > 0.0 ? 0 : 1; // 0: the cell's lower face
  uint base = (uint(cell.x) + uint(gridDims.x) * uint(cell.y)) * 4u + 1u;
  ivec2 faceAt = ivec2(0);
  int faceAxis = -1;
  for (int n = 0; n < 4 && faceAxis < 0; ++n)
  {
    int a = n < 2 ? axis : 1 - axis;
    int face = 2 * a + (n % 2 == 0 ? upper : 1 - upper);
    uvec2 s = WallSlot(ivec3(cell.xy, face));
    if (s.x == base + uint(face))
    {
      faceAt = InSlabs(int(s.y), wallFaceRows);
      faceAxis = a;
    }
  }
  // Off the model where such a wall cuts a step of it: the faces of the columns beside this
  // one that face it (I+ of the column before it in i, I- of the one after, J+, J-).
  for (int n = 0; n < 4 && faceAxis < 0; ++n)
  {
    int a = n / 2;
    ivec2 beside = cell.xy + (a == 0 ? ivec2(n % 2 == 0 ? -1 : 1, 0) : ivec2(0, n % 2 == 0 ? -1 : 1));
    int face = 2 * a + (n % 2 == 0 ? 1 : 0);
    if (all(greaterThanEqual(beside, ivec2(0))) && all(lessThan(beside, gridDims.xy)))
    {
      uvec2 s = WallSlot(ivec3(beside, face));
      uint key = (uint(beside.x) + uint(gridDims.x) * uint(beside.y)) * 4u + 1u + uint(face);
      if (s.x == key)
      {
        faceAt = InSlabs(int(s.y), wallFaceRows);
        faceAxis = a;
        cell.xy = beside; // the wall's own column, whose cells have values
      }
    }
  }
  if (faceAxis < 0)
  {
    return false;
  }
  float along = fract(faceAxis == 0 ? cellCoord.y : cellCoord.x);
  int k = cell.z;
  vec3 t = texelFetch(wallDepths, ivec3(k, faceAt), 0).xyz;
  float top = mix(t.x, t.y, along);
  float bottom = WallDepthAt(faceAt, k + 1, along);
  float slack = 0.5 * depthPerPixel;
  if (modelDepth < top - slack || modelDepth > bottom + slack)
  {
    int lo = 0;
    int hi = gridDims.z - 1;
    for (int s = 0; s < wallSearchSteps && lo < hi; ++s)
    {
      int mid = (lo + hi + 1) / 2;
      if (WallDepthAt(faceAt, mid, along) <= modelDepth)
      {
        lo = mid;
      }
      else
      {
        hi = mid - 1;
      }
    }
    k = lo;
    t = texelFetch(wallDepths, ivec3(k, faceAt), 0).xyz;
    top = mix(t.x, t.y, along);
    bottom = WallDepthAt(faceAt, k + 1, along);
  }
  float perPixel = max(depthPerPixel, 1e-20);
  cell.z = int(t.z);
  lines = vec2(min(abs(modelDepth - top), abs(bottom - modelDepth)), bottom - top) / perPixel;
  return true;
}
#endif

// The plane of a range's cut a cell lies on (K low, K high, I low, I high, J low, J high), or
// -1: the cells a cut exposes lie inside the model, where the hash has no value.
int CutPlane(ivec3 cell)
{
  if (cell.z == cutLow.z)
    return 0;
  if (cell.z == cutHigh.z)
    return 1;
  if (cell.x == cutLow.x)
    return 2;
  if (cell.x == cutHigh.x)
    return 3;
  if (cell.y == cutLow.y)
    return 4;
  return cell.y == cutHigh.y ? 5 : -1;
}

float CutValue(int plane, ivec3 cell)
{
  if (plane == 0)
    return texelFetch(cutLowK, cell.xy, 0).r;
  if (plane == 1)
    return texelFetch(cutHighK, cell.xy, 0).r;
  int along = plane < 4 ? cell.y : cell.x;
  return texelFetch(cutSides, ivec2(along, (plane - 2) * gridDims.z + cell.z), 0).r;
}

#if LIGHTING > 1
// One light's diffuse and specular share at this fragment (`toLight` unit, from the fragment).
void AddLight(vec3 normal, vec3 toEye, vec3 toLight, vec3 lightColor, float attenuation,
  inout vec3 diffuseSum, inout vec3 specularSum)
{
  float df = max(0.0, attenuation * dot(normal, toLight));
  diffuseSum += df * lightColor;
#if SPECULAR
  float sf = sign(df) * attenuation * pow(max(0.0, dot(reflect(-toLight, normal), toEye)), specularPower);
  specularSum += sf * lightColor;
#endif
}
#endif

#if LIGHTING > 2
// A light that may be positional: its direction to the fragment, distance fall-off and cone.
void AddAnyLight(vec3 normal, vec3 toEye, vec3 position, vec3 lightColor, vec3 direction,
  vec3 lightPosition, vec3 falloff, float coneDegrees, float exponent, int positional,
  inout vec3 diffuseSum, inout vec3 specularSum)
{
  if (positional == 0)
  {
    AddLight(normal, toEye, -direction, lightColor, 1.0, diffuseSum, specularSum);
    return;
  }
  vec3 fromLight = position - lightPosition;
  float distance = length(fromLight);
  fromLight /= max(distance, 1e-30);
  float attenuation = 1.0 / (falloff.x + falloff.y * distance + falloff.z * distance * distance);
  if (coneDegrees <= 90.0)
  {
    float along = dot(fromLight, direction);
    attenuation *= along >= cos(radians(coneDegrees)) ? pow(along, exponent) : 0.0;
  }
  AddLight(normal, toEye, -fromLight, lightColor, attenuation, diffuseSum, specularSum);
}
#endif

void main()
{
  // A fragment on a face's edge may interpolate a hair past it: every face drawn belongs to
  // a cell of the grid, or of the range shown.
  ivec3 cell = clamp(ivec3(floor(cellCoord)), cellLow, cellHigh);
  // Side faces span their interfaces: seen edge-on they are slivers on screen, where the
  // interpolated k strays past either interface. Their cell is in the layers the triangle
  // reaches; top and bottom faces keep the k their vertices give.
#if LAYER_VIEW
  if (faceKind == 2)
  {
    cell.z = layer;
  }
#else
  if (faceKind == 2)
  {
    int lowest = max(int(ceil(lastK)) - 1, 0);
    cell.z = sideOneLayer == 1 ? lowest : min(cell.z, lowest);
  }
#endif
#if WALL_DEPTHS
  // Derivatives outside any branch: every fragment of a quad takes them.
  vec3 topoNormal = cross(dFdx(cellCoord), dFdy(cellCoord));
  float depthPerPixel = fwidth(modelDepth);
  bool onWall = false;
  vec2 wallLines = vec2(0.0);
  if (faceKind == 2 && wallLookup == 1)
  {
    onWall = WallCell(cell, topoNormal, depthPerPixel, wallLines);
  }
#endif
#if COLOR_MODE == 2
  {
    // 1 + the natural index, in 24 bits: past 2^24 - 1 cells it wraps to 1, never to the
    // background's 0 (a cell painted black reads as a hole).
    int id = (cell.x + gridDims.x * (cell.y + gridDims.y * cell.z)) % 16777215 + 1;
    gl_FragData[0] = vec4(float(id & 255), float((id >> 8) & 255), float((id >> 16) & 255), 255.0) / 255.0;
  }
#elif COLOR_MODE == 3
  // The pick pass (a float target): the same cell, exact at any grid size.
  gl_FragData[0] = vec4(vec3(cell), 1.0);
#else
#if !LAYER_VIEW
  ivec3 slot = HashSlot(cell);
#endif

  vec3 color = solidColor;
#if COLOR_MODE == 1
  {
#if LAYER_VIEW
    float value = texelFetch(layerProperty, cell.xy, 0).r;
    bool waiting = false;
#else
    float value = texelFetch(propertyTable, slot, 0).r;
    bool waiting = false;
#if CELL_FILTER
    // A cut's cells from its plane's values: in the NaN colour until they are loaded, never
    // in the colour of the cell the hash would name.
    int plane = CutPlane(cell);
    waiting = plane >= 0 && (cutReady / (1 << max(plane, 0))) % 2 == 0;
    value = plane >= 0 ? CutValue(plane, cell) : value;
    if (faceValuesOn == 1)
    {
      value = texelFetch(faceValues, primitiveBase + gl_PrimitiveID).r;
      waiting = false;
    }
#endif
#endif
    if (waiting || isnan(value))
    {
      color = nanColor.rgb;
    }
    else
    {
#if LOG_SCALE
      float v = value > 0.0 ? log(value) / log(10.0) : scalarRange.x;
#else
      float v = value;
#endif
      float span = scalarRange.y - scalarRange.x;
      float t = span > 0.0 ? clamp((v - scalarRange.x) / span, 0.0, 1.0) : 0.5;
      int size = textureSize(colorMap, 0).x;
      color = texelFetch(colorMap, ivec2(min(int(t * float(size)), size - 1), 0), 0).rgb;
    }
  }
#endif

  // Normal (view space), turned to face the eye (two-sided, as VTK lights a surface whose
  // back may show): on tops and bottoms once the normal table is loaded, the original cell's
  // top or bottom face normal (Sec. 5.3); elsewhere the facet's own, per pixel. A layer's
  // cells are mostly inside the model, and the normal table is hashed for the external
  // faces' cells only: a layer lights every face by its facet.
#if TABLE_NORMALS
  // Drawn apart from the sides: the facet's screen derivatives are a large share of a
  // software rasterizer's fragment, and a table normal needs none.
  uvec2 codes = texelFetch(cellNormals, slot, 0).xy;
  vec3 normal = normalize(normalToView * DecodeNormal(faceKind == 0 ? codes.x : codes.y));
  normal = (cameraParallel == 1 ? normal.z < 0.0 : dot(normal, viewPosition) > 0.0) ? -normal : normal;
#else
  vec3 normal = normalize(cross(dFdx(viewPosition), dFdy(viewPosition)));
  normal = (cameraParallel == 1 ? normal.z < 0.0 : dot(normal, viewPosition) > 0.0) ? -normal : normal;
#endif
#if COLOR_MODE == 1
  vec3 ambientPart = ambientIntensity * color; // a property's colour is ambient and diffuse
#else
  vec3 ambientPart = ambientColorUniform;
#endif
  vec3 diffusePart = diffuseIntensity * color;
#if LIGHTING == 0
  color = ambientPart + diffusePart;
#else
  vec3 diffuseSum = vec3(0.0);
  vec3 specularSum = vec3(0.0);
#if LIGHTING == 1
  float df = max(0.0, normal.z);
  diffuseSum = df * lightColor0;
#if SPECULAR
  specularSum = pow(df, specularPower) * lightColor0;
#endif
#else
  vec3 toEye = normalize(-viewPosition);
  //RESMR::Lights
#endif
  color = ambientPart + diffusePart * diffuseSum + specularColorUniform * specularSum;
#endif

#if GRID_LINES
  {
    // Distance to the nearest integer of each coordinate, in pixels; the constant axis sits
    // half a cell from any integer with a zero derivative, so it never makes a line.
    // Drawn at a reduced scale, lines keep their width on the view (at least a drawn pixel)
    // and fade where cells shrink below the same size on the view.
    vec3 perPixel = max(fwidth(cellCoord), vec3(1e-6));
    vec3 pixels = abs(fract(cellCoord + 0.5) - 0.5) / perPixel;
    vec3 cellPixels = 1.0 / (perPixel * renderScale);
#if WALL_DEPTHS
    // A wall's layer lines where its true interfaces are.
    pixels.z = onWall ? wallLines.x : pixels.z;
    cellPixels.z = onWall ? wallLines.y / renderScale : cellPixels.z;
#endif
    vec3 fade = smoothstep(vec3(3.0), vec3(8.0), cellPixels);
    float width = max(gridLineWidth * renderScale, min(gridLineWidth, 1.0));
    vec3 line = (1.0 - smoothstep(vec3(0.5 * width - 0.5), vec3(0.5 * width + 0.5), pixels)) * fade;
    float strength = max(line.x, max(line.y, line.z));
    color = mix(color, gridLineColor, strength);
  }
#endif
  gl_FragData[0] = vec4(color, 1.0);
#endif
}
