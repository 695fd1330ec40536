// Draws a PmMesh with WebGL2: faces shaded by their normals (the PM's where it has them, else
// flat from the screen-space derivatives of the position), coloured by the PM's colours or a
// checker of its texture coordinates where it has them; an optional wireframe; an orbit camera
// (drag to turn, wheel to zoom) framed on the PM's bounding box, which the header gives before
// any split arrives. A PM without attributes is drawn indexed (a vertex per PM vertex), one
// with attributes corner by corner (a corner's wedge holds its values).

const VERTEX = `#version 300 es
uniform mat4 viewProjection;
in vec3 position;
in vec3 normal;
in vec2 uv;
in vec4 color;
out vec3 world;
out vec3 vNormal;
out vec2 vUv;
out vec4 vColor;
void main() {
  world = position;
  vNormal = normal;
  vUv = uv;
  vColor = color;
  gl_Position = viewProjection * vec4(position, 1.0);
}`;

const FRAGMENT = `#version 300 es
precision highp float;
uniform vec3 light;
uniform vec4 colour;
uniform bool lines, hasNormal, hasUv, hasColor, silhouette;
in vec3 world;
in vec3 vNormal;
in vec2 vUv;
in vec4 vColor;
out vec4 outColour;
void main() {
  if (lines) { outColour = colour; return; }
  if (silhouette) { outColour = vec4(1.0); return; }
  vec3 n = hasNormal && dot(vNormal, vNormal) > 0.0 ? normalize(vNormal)
                                                   : normalize(cross(dFdx(world), dFdy(world)));
  vec3 base = colour.rgb;
  if (hasColor) base = vColor.rgb;
  else if (hasUv) base = mod(floor(vUv.x * 16.0) + floor(vUv.y * 16.0), 2.0) < 1.0
                             ? vec3(0.92, 0.9, 0.85) : vec3(0.35, 0.45, 0.8);
  float lit = 0.25 + 0.75 * abs(dot(n, light));
  outColour = vec4(base * lit, 1.0);
}`;

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
  return shader;
}

function multiply(a, b) {
  const out = new Float32Array(16);
  for (let i = 0; i < 4; i++)
    for (let j = 0; j < 4; j++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + j] * b[i * 4 + k];
      out[i * 4 + j] = s;
    }
  return out;
}

export class Renderer {
  constructor(canvas, header) {
    this.canvas = canvas;
    const gl = canvas.getContext('webgl2', {antialias: true});
    if (!gl) throw new Error('this browser has no WebGL2');
    this.gl = gl;
    const program = gl.createProgram();
    gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT));
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
    this.program = program;
    this.uniforms = {};
    for (const name of ['viewProjection', 'light', 'colour', 'lines', 'hasNormal', 'hasUv', 'hasColor', 'silhouette'])
      this.uniforms[name] = gl.getUniformLocation(program, name);
    this.vao = gl.createVertexArray();
    gl.bindVertexArray(this.vao);
    // With attributes, a GPU vertex per face corner.
    this.layout = header.floatsPerWedge ? header.layout : null;
    this.floatsPerWedge = header.floatsPerWedge;
    const vertices = this.layout ? 3 * header.fullFaces : header.fullVertices;
    this.positionBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, this.positionBuffer);
    gl.bufferData(gl.ARRAY_BUFFER, 4 * 3 * vertices, gl.DYNAMIC_DRAW);
    const location = gl.getAttribLocation(program, 'position');
    gl.enableVertexAttribArray(location);
    gl.vertexAttribPointer(location, 3, gl.FLOAT, false, 0, 0);
    // The wedge values of each corner, interleaved as the PM keeps them: normal, uv, colour.
    const F = this.floatsPerWedge;
    let offset = 0;
    if (this.layout) {
      this.valueBuffer = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, this.valueBuffer);
      gl.bufferData(gl.ARRAY_BUFFER, 4 * F * vertices, gl.DYNAMIC_DRAW);
    }
    for (const [name, size, present] of [['normal', 3, this.layout?.normal], ['uv', 2, this.layout?.texcoord],
      ['color', 4, this.layout?.color]]) {
      const at = gl.getAttribLocation(program, name);
      if (at < 0) continue;
      if (present) {
        gl.enableVertexAttribArray(at);
        gl.vertexAttribPointer(at, size, gl.FLOAT, false, 4 * F, 4 * offset);
        offset += size;
      } else {
        gl.disableVertexAttribArray(at);
      }
    }
    this.indexBuffer = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indexBuffer);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, 4 * 3 * header.fullFaces, gl.DYNAMIC_DRAW);
    this.lineBuffer = gl.createBuffer();
    this.indexCount = 0;
    this.lineCount = 0;
    this.wireframe = false;
    const center = [0, 1, 2].map((k) => (header.boxMin[k] + header.boxMax[k]) / 2);
    const size = Math.hypot(...[0, 1, 2].map((k) => header.boxMax[k] - header.boxMin[k])) || 1;
    this.camera = {center, distance: 1.6 * size, size, yaw: 0.6, pitch: 0.3};
    this.#bindControls();
  }

  // The mesh's level into the buffers (the positions of every vertex reached, the level's faces).
  update(mesh) {
    if (this.layout) return this.#updateCorners(mesh);
    const gl = this.gl;
    gl.bindVertexArray(this.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.positionBuffer);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, mesh.positions, 0, 3 * mesh.vertexCount);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indexBuffer);
    gl.bufferSubData(gl.ELEMENT_ARRAY_BUFFER, 0, mesh.faces, 0, 3 * mesh.faceCount);
    this.indexCount = 3 * mesh.faceCount;
    if (this.wireframe) {
      const lines = new Uint32Array(6 * mesh.faceCount);
      for (let f = 0; f < mesh.faceCount; f++)
        for (let k = 0; k < 3; k++) {
          lines[6 * f + 2 * k] = mesh.faces[3 * f + k];
          lines[6 * f + 2 * k + 1] = mesh.faces[3 * f + ((k + 1) % 3)];
        }
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.lineBuffer);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, lines, gl.DYNAMIC_DRAW);
      this.lineCount = lines.length;
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indexBuffer);
    }
  }

  // A PM with attributes: each corner's position and its wedge's values.
  #updateCorners(mesh) {
    const gl = this.gl, n = 3 * mesh.faceCount, F = this.floatsPerWedge;
    const positions = new Float32Array(3 * n), values = new Float32Array(F * n);
    for (let c = 0; c < n; c++) {
      const v = mesh.faces[c], w = mesh.cornerWedges[c];
      positions[3 * c] = mesh.positions[3 * v];
      positions[3 * c + 1] = mesh.positions[3 * v + 1];
      positions[3 * c + 2] = mesh.positions[3 * v + 2];
      for (let k = 0; k < F; k++) values[F * c + k] = mesh.wedgeValues[F * w + k];
    }
    gl.bindVertexArray(this.vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.positionBuffer);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, positions);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.valueBuffer);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, values);
    this.cornerCount = n;
    if (this.wireframe) {
      const lines = new Uint32Array(2 * n);
      for (let c = 0; c < n; c++) {
        lines[2 * c] = c;
        lines[2 * c + 1] = c % 3 === 2 ? c - 2 : c + 1;
      }
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.lineBuffer);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, lines, gl.DYNAMIC_DRAW);
      this.lineCount = lines.length;
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indexBuffer);
    }
  }

  draw() {
    const gl = this.gl, canvas = this.canvas;
    const width = canvas.clientWidth * devicePixelRatio, height = canvas.clientHeight * devicePixelRatio;
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
    }
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.11, 0.125, 0.15, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(this.program);
    gl.bindVertexArray(this.vao);
    gl.uniformMatrix4fv(this.uniforms.viewProjection, false, this.#viewProjection());
    const c = this.camera;
    gl.uniform3f(this.uniforms.light, Math.cos(c.pitch) * Math.sin(c.yaw), Math.sin(c.pitch), Math.cos(c.pitch) * Math.cos(c.yaw));
    gl.uniform1i(this.uniforms.lines, 0);
    gl.uniform4f(this.uniforms.colour, 0.85, 0.8, 0.7, 1);
    gl.enable(gl.POLYGON_OFFSET_FILL);
    gl.polygonOffset(1, 1);
    gl.uniform1i(this.uniforms.silhouette, this.silhouette ? 1 : 0);
    gl.uniform1i(this.uniforms.hasNormal, this.layout?.normal ? 1 : 0);
    gl.uniform1i(this.uniforms.hasUv, this.layout?.texcoord ? 1 : 0);
    gl.uniform1i(this.uniforms.hasColor, this.layout?.color ? 1 : 0);
    if (this.layout) gl.drawArrays(gl.TRIANGLES, 0, this.cornerCount || 0);
    else gl.drawElements(gl.TRIANGLES, this.indexCount, gl.UNSIGNED_INT, 0);
    if (this.wireframe && this.lineCount && !this.silhouette) {
      gl.uniform1i(this.uniforms.lines, 1);
      gl.uniform4f(this.uniforms.colour, 0.1, 0.1, 0.1, 1);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.lineBuffer);
      gl.drawElements(gl.LINES, this.lineCount, gl.UNSIGNED_INT, 0);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, this.indexBuffer);
    }
  }

  // The canvas drawn now, read back (RGBA, bottom row first): for tests and benchmarks. With
  // `silhouette`, every face white and unlit, no wireframe.
  snapshot(silhouette = false) {
    this.silhouette = silhouette;
    this.draw();
    this.silhouette = false;
    const gl = this.gl, w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const pixels = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    return pixels;
  }

  // The fraction of the canvas's pixels the mesh covers (not the background's colour).
  coverage() {
    const pixels = this.snapshot();
    let covered = 0;
    for (let i = 0; i < pixels.length; i += 4) if (Math.abs(pixels[i] - 28) > 8) covered++;
    return covered / (pixels.length / 4);
  }

  // What view-dependent refinement needs of the view: the view-projection matrix (column
  // major), the projection's scale (1 / tan(fov / 2)) and the canvas's height in pixels.
  view() {
    return {viewProjection: this.#viewProjection(), scale: 1 / Math.tan((45 * Math.PI) / 360),
      height: this.canvas.height || this.canvas.clientHeight * devicePixelRatio};
  }

  #viewProjection() {
    const c = this.camera;
    const eye = [
      c.center[0] + c.distance * Math.cos(c.pitch) * Math.sin(c.yaw),
      c.center[1] + c.distance * Math.sin(c.pitch),
      c.center[2] + c.distance * Math.cos(c.pitch) * Math.cos(c.yaw),
    ];
    const f = [0, 1, 2].map((k) => c.center[k] - eye[k]);
    const fl = Math.hypot(...f);
    const fw = f.map((x) => x / fl);
    let s = [fw[1] * 0 - fw[2] * 1, fw[2] * 0 - fw[0] * 0, fw[0] * 1 - fw[1] * 0];
    const sl = Math.hypot(...s) || 1;
    s = s.map((x) => x / sl);
    const u = [s[1] * fw[2] - s[2] * fw[1], s[2] * fw[0] - s[0] * fw[2], s[0] * fw[1] - s[1] * fw[0]];
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const view = new Float32Array([s[0], u[0], -fw[0], 0, s[1], u[1], -fw[1], 0, s[2], u[2], -fw[2], 0,
      -dot(s, eye), -dot(u, eye), dot(fw, eye), 1]);
    const near = Math.max(c.distance - c.size, c.size * 1e-3), far = c.distance + c.size;
    const aspect = this.canvas.width / Math.max(1, this.canvas.height);
    const t = 1 / Math.tan((45 * Math.PI) / 360);
    const projection = new Float32Array([t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (far + near) / (near - far), -1,
      0, 0, (2 * far * near) / (near - far), 0]);
    return multiply(projection, view);
  }

  #bindControls() {
    const canvas = this.canvas, c = this.camera;
    let last = null;
    canvas.addEventListener('pointerdown', (e) => {
      last = [e.clientX, e.clientY];
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointerup', () => (last = null));
    canvas.addEventListener('pointermove', (e) => {
      if (!last) return;
      c.yaw -= (e.clientX - last[0]) * 0.01;
      c.pitch = Math.max(-1.5, Math.min(1.5, c.pitch + (e.clientY - last[1]) * 0.01));
      last = [e.clientX, e.clientY];
      if (this.onCameraChange) this.onCameraChange();
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      c.distance = Math.max(c.size * 0.05, c.distance * Math.exp(e.deltaY * 0.001));
      if (this.onCameraChange) this.onCameraChange();
    }, {passive: false});
  }
}
