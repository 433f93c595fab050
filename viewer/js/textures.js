// KTX2 files of a bake as WebGL2 textures. The container is parsed by the npm package ktx-parse
// (served by scripts/view at /vendor/ktx-parse/), so the viewer reads the files with a reader
// independent of skybake's own (tools/core/lut/ktx2.h). Only the formats skybake writes are
// accepted (docs/lut-pack.md, docs/fog.md, docs/clouds.md); anything else is an error that names
// the file.
import { read } from "/vendor/ktx-parse/index.mjs";

// Vulkan format numbers (the Vulkan registry's VkFormat) -> WebGL2 upload parameters.
const VK = {
  R8_UNORM: 9,
  R8G8_UNORM: 16,
  R8G8B8A8_UNORM: 37,
  R16_SFLOAT: 76,
  R32G32B32A32_SFLOAT: 109,
  B10G11R11_UFLOAT_PACK32: 122,
};

function uploadFormat(gl, vk) {
  switch (vk) {
    case VK.R8_UNORM: return { internal: gl.R8, format: gl.RED, type: gl.UNSIGNED_BYTE, view: (b) => b, filterable: true };
    case VK.R8G8_UNORM: return { internal: gl.RG8, format: gl.RG, type: gl.UNSIGNED_BYTE, view: (b) => b, filterable: true };
    case VK.R8G8B8A8_UNORM: return { internal: gl.RGBA8, format: gl.RGBA, type: gl.UNSIGNED_BYTE, view: (b) => b, filterable: true };
    case VK.R16_SFLOAT:
      return { internal: gl.R16F, format: gl.RED, type: gl.HALF_FLOAT, view: (b) => new Uint16Array(b.buffer, b.byteOffset, b.byteLength / 2), filterable: true };
    case VK.R32G32B32A32_SFLOAT:
      // RGBA32F is not filterable in WebGL2 without OES_texture_float_linear: read with texelFetch.
      return { internal: gl.RGBA32F, format: gl.RGBA, type: gl.FLOAT, view: (b) => new Float32Array(b.buffer, b.byteOffset, b.byteLength / 4), filterable: false };
    case VK.B10G11R11_UFLOAT_PACK32:
      // The Vulkan packed format's bit layout (R bits 0-10, G 11-21, B 22-31) is GL's
      // UNSIGNED_INT_10F_11F_11F_REV; R11F_G11F_B10F is filterable in WebGL2.
      return { internal: gl.R11F_G11F_B10F, format: gl.RGB, type: gl.UNSIGNED_INT_10F_11F_11F_REV, view: (b) => new Uint32Array(b.buffer, b.byteOffset, b.byteLength / 4), filterable: true };
    default:
      return null;
  }
}

const decoder = new TextDecoder();

// A KTX2 key's value as a string (ktx-parse keeps unknown keys as bytes; skybake's values are
// NUL-terminated UTF-8).
export function keyString(container, key) {
  const v = container.keyValue[key];
  if (v === undefined) return undefined;
  if (typeof v === "string") return v;
  let end = v.length;
  while (end > 0 && v[end - 1] === 0) end--;
  return decoder.decode(v.subarray(0, end));
}

export function keyNumbers(container, key, file) {
  const s = keyString(container, key);
  if (s === undefined) throw new Error(`${file}: KTX2 key '${key}' is missing`);
  const n = s.trim().split(/\s+/).map(Number);
  if (n.some((x) => !Number.isFinite(x))) throw new Error(`${file}: KTX2 key '${key}' is not a list of numbers: "${s}"`);
  return n;
}

export async function fetchBytes(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
  return new Uint8Array(await r.arrayBuffer());
}

// Loads a KTX2 file and uploads it: 2D, 2D array (layers > 0) or 3D (depth > 0). Wrap: CLAMP_TO_EDGE
// (the LUTs) unless `repeat` (the tiling noise volumes). Returns {texture, target, container, width,
// height, depth, layers, file}.
export async function loadKtx2(gl, url, { repeat = false } = {}) {
  const container = read(await fetchBytes(url));
  const f = uploadFormat(gl, container.vkFormat);
  if (!f) throw new Error(`${url}: VkFormat ${container.vkFormat} is not one skybake writes`);
  if (container.supercompressionScheme !== 0) throw new Error(`${url}: supercompressed KTX2 files are not supported`);
  const w = container.pixelWidth, h = Math.max(1, container.pixelHeight);
  const d = container.pixelDepth, layers = container.layerCount;
  let bytes = container.levels[0].levelData;
  if (bytes.byteOffset % 4 !== 0) bytes = bytes.slice();  // typed views of 2- and 4-byte texels need alignment
  const data = f.view(bytes);
  const tex = gl.createTexture();
  let target;
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  if (d > 0) {
    target = gl.TEXTURE_3D;
    gl.bindTexture(target, tex);
    gl.texImage3D(target, 0, f.internal, w, h, d, 0, f.format, f.type, data);
  } else if (layers > 0) {
    target = gl.TEXTURE_2D_ARRAY;
    gl.bindTexture(target, tex);
    gl.texImage3D(target, 0, f.internal, w, h, layers, 0, f.format, f.type, data);
  } else {
    target = gl.TEXTURE_2D;
    gl.bindTexture(target, tex);
    gl.texImage2D(target, 0, f.internal, w, h, 0, f.format, f.type, data);
  }
  const filter = f.filterable ? gl.LINEAR : gl.NEAREST;
  const wrap = repeat ? gl.REPEAT : gl.CLAMP_TO_EDGE;
  gl.texParameteri(target, gl.TEXTURE_MIN_FILTER, filter);
  gl.texParameteri(target, gl.TEXTURE_MAG_FILTER, filter);
  gl.texParameteri(target, gl.TEXTURE_WRAP_S, wrap);
  gl.texParameteri(target, gl.TEXTURE_WRAP_T, wrap);
  gl.texParameteri(target, gl.TEXTURE_WRAP_R, wrap);
  gl.bindTexture(target, null);
  const err = gl.getError();
  if (err !== gl.NO_ERROR) throw new Error(`${url}: WebGL error 0x${err.toString(16)} uploading ${w}x${h}x${Math.max(d, layers)}`);
  return { texture: tex, target, container, width: w, height: h, depth: d, layers, file: url };
}
