"""Mesa's llvmpipe as a sampling reference: an off-screen OpenGL 4.5 core
context (EGL through moderngl/glcontext), textures with explicitly uploaded
levels, sampler objects with every GL state parvo's sampler has, and a
compute shader that runs one texture function per query of a buffer.

Not a check itself (the leading underscore keeps .ci/interop.sh from running
it); scripts/interop/gl_sampling.py drives it.

Why ctypes beside moderngl: moderngl wraps programs, buffers and dispatches
well, but its textures cannot take DEPTH_COMPONENT32F data or caller-made
levels of awkward sizes, and its samplers have no LOD bias or
MIRROR_CLAMP_TO_EDGE. Those few calls go straight to the GL entry points
(eglGetProcAddress), on the context moderngl made current.
"""
import ctypes
import os

import numpy as np

# GL enums (OpenGL 4.5 core, glcorearb.h).
TEXTURE_2D = 0x0DE1
TEXTURE_CUBE_MAP = 0x8513
TEXTURE_CUBE_MAP_POSITIVE_X = 0x8515  # + face index: +X -X +Y -Y +Z -Z
TEXTURE_CUBE_MAP_SEAMLESS = 0x884F
TEXTURE_MAX_ANISOTROPY = 0x84FE
TEXTURE0 = 0x84C0
FLOAT = 0x1406
RGBA = 0x1908
RGBA32F = 0x8814
DEPTH_COMPONENT = 0x1902
DEPTH_COMPONENT32F = 0x8CAC
UNPACK_ALIGNMENT = 0x0CF5
TEXTURE_BASE_LEVEL = 0x813C
TEXTURE_MAX_LEVEL = 0x813D
TEXTURE_MAG_FILTER = 0x2800
TEXTURE_MIN_FILTER = 0x2801
TEXTURE_WRAP_S = 0x2802
TEXTURE_WRAP_T = 0x2803
TEXTURE_BORDER_COLOR = 0x1004
TEXTURE_MIN_LOD = 0x813A
TEXTURE_MAX_LOD = 0x813B
TEXTURE_LOD_BIAS = 0x8501
TEXTURE_COMPARE_MODE = 0x884C
TEXTURE_COMPARE_FUNC = 0x884D
COMPARE_REF_TO_TEXTURE = 0x884E
NONE = 0
NEAREST = 0x2600
LINEAR = 0x2601
MIN_FILTER = {  # (texel filter, mip mode) -> GL minification filter
    ("nearest", "none"): 0x2600, ("linear", "none"): 0x2601,
    ("nearest", "nearest"): 0x2700, ("linear", "nearest"): 0x2701,
    ("nearest", "linear"): 0x2702, ("linear", "linear"): 0x2703,
}
MAG_FILTER = {"nearest": NEAREST, "linear": LINEAR}
WRAP = {  # parvo's wrap names -> GL
    "repeat": 0x2901, "mirror": 0x8370, "clamp": 0x812F,
    "border": 0x812D, "mirror-clamp": 0x8743,
}
COMPARE = {  # parvo's compare names -> GL compare functions
    "never": 0x0200, "less": 0x0201, "equal": 0x0202, "lequal": 0x0203,
    "greater": 0x0204, "notequal": 0x0205, "gequal": 0x0206, "always": 0x0207,
}


def _software_env():
    """Pin Mesa's EGL vendor and the llvmpipe driver, so a machine with a GPU
    (or softpipe as the default) still runs the reference this check names."""
    os.environ.setdefault("__EGL_VENDOR_LIBRARY_FILENAMES", "/usr/share/glvnd/egl_vendor.d/50_mesa.json")
    os.environ.setdefault("GALLIUM_DRIVER", "llvmpipe")
    os.environ.setdefault("LIBGL_ALWAYS_SOFTWARE", "1")
    os.environ.setdefault("EGL_PLATFORM", "surfaceless")


class GL:
    """One llvmpipe context and the raw entry points the harness needs."""

    def __init__(self):
        _software_env()
        import moderngl

        self.mgl = moderngl
        # The runtime sonames (libEGL.so.1, libGL.so.1), not the unversioned
        # names of the -dev packages, which a fresh machine may lack.
        self.ctx = moderngl.create_standalone_context(require=450, backend="egl", libegl="libEGL.so.1",
                                                      libgl="libGL.so.1")
        self.renderer = self.ctx.info["GL_RENDERER"]
        self.version = self.ctx.info["GL_VERSION"]
        egl = ctypes.CDLL("libEGL.so.1")
        egl.eglGetProcAddress.restype = ctypes.c_void_p
        egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
        u, i, f, p = ctypes.c_uint, ctypes.c_int, ctypes.c_float, ctypes.c_void_p

        def fn(name, *argtypes, restype=None):
            addr = egl.eglGetProcAddress(name.encode())
            if not addr:
                raise RuntimeError(f"no GL entry point {name}")
            return ctypes.CFUNCTYPE(restype, *argtypes)(addr)

        self.GenTextures = fn("glGenTextures", i, ctypes.POINTER(u))
        self.DeleteTextures = fn("glDeleteTextures", i, ctypes.POINTER(u))
        self.BindTexture = fn("glBindTexture", u, u)
        self.ActiveTexture = fn("glActiveTexture", u)
        self.TexImage2D = fn("glTexImage2D", u, i, i, i, i, i, u, u, p)
        self.TexParameteri = fn("glTexParameteri", u, u, i)
        self.PixelStorei = fn("glPixelStorei", u, i)
        self.GenSamplers = fn("glGenSamplers", i, ctypes.POINTER(u))
        self.DeleteSamplers = fn("glDeleteSamplers", i, ctypes.POINTER(u))
        self.BindSampler = fn("glBindSampler", u, u)
        self.SamplerParameteri = fn("glSamplerParameteri", u, u, i)
        self.SamplerParameterf = fn("glSamplerParameterf", u, u, f)
        self.SamplerParameterfv = fn("glSamplerParameterfv", u, u, ctypes.POINTER(f))
        self.GetError = fn("glGetError", restype=u)
        self.Enable = fn("glEnable", u)
        self.programs = {}

    def check_error(self, what):
        e = self.GetError()
        if e:
            raise RuntimeError(f"GL error 0x{e:04x} in {what}")

    def texture(self, levels, depth=False, unit=0):
        """A 2D texture on unit 0 whose level k is levels[k] (H x W x 4 float32
        RGBA, or H x W float32 depth), uploaded as given: RGBA32F, or
        DEPTH_COMPONENT32F from channel 0. BASE_LEVEL 0, MAX_LEVEL the last
        given level, so a partial chain is complete too."""
        name = ctypes.c_uint(0)
        self.GenTextures(1, ctypes.byref(name))
        self.ActiveTexture(TEXTURE0 + unit)
        self.BindTexture(TEXTURE_2D, name.value)
        self.PixelStorei(UNPACK_ALIGNMENT, 1)
        for k, lv in enumerate(levels):
            a = np.ascontiguousarray(lv, dtype=np.float32)
            h, w = a.shape[:2]
            if depth:
                self.TexImage2D(TEXTURE_2D, k, DEPTH_COMPONENT32F, w, h, 0, DEPTH_COMPONENT, FLOAT,
                                a.ctypes.data)
            else:
                self.TexImage2D(TEXTURE_2D, k, RGBA32F, w, h, 0, RGBA, FLOAT, a.ctypes.data)
            self.check_error(f"glTexImage2D level {k}")
        self.TexParameteri(TEXTURE_2D, TEXTURE_BASE_LEVEL, 0)
        self.TexParameteri(TEXTURE_2D, TEXTURE_MAX_LEVEL, len(levels) - 1)
        self.check_error("texture levels")
        self.ActiveTexture(TEXTURE0)
        return name.value

    def cube_texture(self, faces):
        """A cube map on unit 0: faces[f][k] is face f's level k (H x W x 4
        float32, faces in GL's order +X -X +Y -Y +Z -Z), with seamless
        filtering on (GL_TEXTURE_CUBE_MAP_SEAMLESS, off by default in GL)."""
        name = ctypes.c_uint(0)
        self.GenTextures(1, ctypes.byref(name))
        self.ActiveTexture(TEXTURE0)
        self.BindTexture(TEXTURE_CUBE_MAP, name.value)
        self.PixelStorei(UNPACK_ALIGNMENT, 1)
        for f, levels in enumerate(faces):
            for k, lv in enumerate(levels):
                a = np.ascontiguousarray(lv, dtype=np.float32)
                h, w = a.shape[:2]
                self.TexImage2D(TEXTURE_CUBE_MAP_POSITIVE_X + f, k, RGBA32F, w, h, 0, RGBA, FLOAT,
                                a.ctypes.data)
                self.check_error(f"glTexImage2D face {f} level {k}")
        self.TexParameteri(TEXTURE_CUBE_MAP, TEXTURE_BASE_LEVEL, 0)
        self.TexParameteri(TEXTURE_CUBE_MAP, TEXTURE_MAX_LEVEL, len(faces[0]) - 1)
        self.Enable(TEXTURE_CUBE_MAP_SEAMLESS)
        self.check_error("cube texture")
        return name.value

    def run_cube(self, queries, max_aniso=1.0):
        """textureGrad(samplerCube) for N queries (N x 9 float32: direction,
        its x derivative, its y derivative) on the cube bound to unit 0 (the
        sampler bound there, its max anisotropy set to `max_aniso`);
        returns N x 4 float32."""
        key = "cube grad"
        if key not in self.programs:
            self.programs[key] = self.ctx.compute_shader("""#version 450
layout(local_size_x = 64) in;
layout(binding = 0) uniform samplerCube tex;
layout(std430, binding = 0) readonly buffer Queries { float q[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 r[]; };
uniform uint count;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    uint b = 9u * i;
    vec3 d = vec3(q[b], q[b + 1u], q[b + 2u]);
    vec3 dx = vec3(q[b + 3u], q[b + 4u], q[b + 5u]);
    vec3 dy = vec3(q[b + 6u], q[b + 7u], q[b + 8u]);
    r[i] = textureGrad(tex, d, dx, dy);
}
""")
        prog = self.programs[key]
        q = np.ascontiguousarray(queries, dtype=np.float32)
        n = len(q)
        qbuf = self.ctx.buffer(q.tobytes())
        rbuf = self.ctx.buffer(reserve=max(16, n * 16))
        qbuf.bind_to_storage_buffer(0)
        rbuf.bind_to_storage_buffer(1)
        prog["count"].value = n
        prog.run(group_x=(n + 63) // 64)
        out = np.frombuffer(rbuf.read(), dtype=np.float32)[: n * 4].reshape(n, 4).copy()
        qbuf.release()
        rbuf.release()
        self.check_error("compute cube grad")
        return out

    def bind(self, name):
        """Bind texture `name` to unit 0, where every lookup samples."""
        self.ActiveTexture(TEXTURE0)
        self.BindTexture(TEXTURE_2D, name)

    def delete_texture(self, name):
        n = ctypes.c_uint(name)
        self.DeleteTextures(1, ctypes.byref(n))

    def sampler(self, mag="linear", min="linear", mip="none", wrap=("repeat", "repeat"),
                border=(0.0, 0.0, 0.0, 0.0), lod_bias=0.0, lod_min=-1000.0, lod_max=1000.0,
                compare=None):
        """A sampler object bound to unit 0 with parvo's sampler options in GL
        terms (GL's defaults for what is not given)."""
        name = ctypes.c_uint(0)
        self.GenSamplers(1, ctypes.byref(name))
        s = name.value
        self.SamplerParameteri(s, TEXTURE_MAG_FILTER, MAG_FILTER[mag])
        self.SamplerParameteri(s, TEXTURE_MIN_FILTER, MIN_FILTER[(min, mip)])
        self.SamplerParameteri(s, TEXTURE_WRAP_S, WRAP[wrap[0]])
        self.SamplerParameteri(s, TEXTURE_WRAP_T, WRAP[wrap[1]])
        self.SamplerParameterfv(s, TEXTURE_BORDER_COLOR, (ctypes.c_float * 4)(*border))
        self.SamplerParameterf(s, TEXTURE_LOD_BIAS, lod_bias)
        self.SamplerParameterf(s, TEXTURE_MIN_LOD, lod_min)
        self.SamplerParameterf(s, TEXTURE_MAX_LOD, lod_max)
        if compare is None:
            self.SamplerParameteri(s, TEXTURE_COMPARE_MODE, NONE)
        else:
            self.SamplerParameteri(s, TEXTURE_COMPARE_MODE, COMPARE_REF_TO_TEXTURE)
            self.SamplerParameteri(s, TEXTURE_COMPARE_FUNC, COMPARE[compare])
        self.check_error("sampler parameters")
        self.BindSampler(0, s)
        return s

    def set_max_anisotropy(self, sampler, n):
        """GL 4.6 / EXT_texture_filter_anisotropic maximum anisotropy."""
        self.SamplerParameterf(sampler, TEXTURE_MAX_ANISOTROPY, float(n))
        self.check_error("max anisotropy")

    def delete_sampler(self, name):
        n = ctypes.c_uint(name)
        self.BindSampler(0, 0)
        self.DeleteSamplers(1, ctypes.byref(n))

    # One GLSL expression per texture function. Each query is two vec4s:
    # a = (u, v, du/dx, dv/dx), b = (du/dy, dv/dy, ref, lod).
    CALLS = {
        "grad": ("sampler2D", "textureGrad(tex, a.xy, a.zw, b.xy)"),
        "lod": ("sampler2D", "textureLod(tex, a.xy, b.w)"),
        "gather0": ("sampler2D", "textureGather(tex, a.xy, 0)"),
        "gather1": ("sampler2D", "textureGather(tex, a.xy, 1)"),
        "gather2": ("sampler2D", "textureGather(tex, a.xy, 2)"),
        "gather3": ("sampler2D", "textureGather(tex, a.xy, 3)"),
        "shadow_grad": ("sampler2DShadow", "vec4(textureGrad(tex, vec3(a.xy, b.z), a.zw, b.xy))"),
        "shadow_lod": ("sampler2DShadow", "vec4(textureLod(tex, vec3(a.xy, b.z), b.w))"),
    }

    def _program(self, call):
        if call not in self.programs:
            sampler_type, expr = self.CALLS[call]
            src = f"""#version 450
layout(local_size_x = 64) in;
layout(binding = 0) uniform {sampler_type} tex;
layout(std430, binding = 0) readonly buffer Queries {{ vec4 q[]; }};
layout(std430, binding = 1) writeonly buffer Results {{ vec4 r[]; }};
uniform uint count;
void main() {{
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 a = q[2u * i];
    vec4 b = q[2u * i + 1u];
    r[i] = {expr};
}}
"""
            self.programs[call] = self.ctx.compute_shader(src)
        return self.programs[call]

    def run(self, call, queries):
        """Run texture function `call` on texture unit 0 (texture and sampler
        bound there) for N queries (N x 8 float32: u, v, dudx, dvdx, dudy,
        dvdy, ref, lod); returns N x 4 float32."""
        q = np.ascontiguousarray(queries, dtype=np.float32)
        n = len(q)
        prog = self._program(call)
        qbuf = self.ctx.buffer(q.tobytes())
        rbuf = self.ctx.buffer(reserve=max(16, n * 16))
        qbuf.bind_to_storage_buffer(0)
        rbuf.bind_to_storage_buffer(1)
        if "count" in prog:
            prog["count"].value = n
        prog.run(group_x=(n + 63) // 64)
        out = np.frombuffer(rbuf.read(), dtype=np.float32)[: n * 4].reshape(n, 4).copy()
        qbuf.release()
        rbuf.release()
        self.check_error(f"compute {call}")
        return out

    # Fragment-shader lookups with implicit derivatives and the shader's
    # bias argument: what `texture(s, uv, bias)` does in a fragment shader.
    FRAGMENT_CALLS = {
        "bias": ("sampler2D", "texture(tex, uv, shader_bias)"),
        "shadow_bias": ("sampler2DShadow", "vec4(texture(tex, vec3(uv, b.z), shader_bias))"),
    }

    def _fragment_program(self, call):
        key = "fragment " + call
        if key not in self.programs:
            sampler_type, expr = self.FRAGMENT_CALLS[call]
            vs = """#version 450
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1)) - 1.0;
    gl_Position = vec4(p, 0.0, 1.0);
}
"""
            # Query i owns the 2x2 pixel quad at (2x, 2y); its pixels sample
            # at uv + sx * (du/dx, dv/dx) + sy * (du/dy, dv/dy), so the
            # quad's finite differences, which are the implicit derivatives,
            # are the query's derivatives, and pixel (2x, 2y) samples at uv.
            fs = f"""#version 450
layout(binding = 0) uniform {sampler_type} tex;
layout(binding = 1) uniform sampler2D queries;
uniform int columns;
uniform float shader_bias;
out vec4 color;
void main() {{
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 s = p & 1;
    int i = (p.y >> 1) * columns + (p.x >> 1);
    ivec2 at = ivec2(2 * (i % columns), i / columns);
    vec4 a = texelFetch(queries, at, 0);
    vec4 b = texelFetch(queries, at + ivec2(1, 0), 0);
    vec2 uv = a.xy + float(s.x) * a.zw + float(s.y) * b.xy;
    color = {expr};
}}
"""
            prog = self.ctx.program(vertex_shader=vs, fragment_shader=fs)
            self.programs[key] = (prog, self.ctx.vertex_array(prog, []))
        return self.programs[key]

    def run_fragment(self, call, queries, shader_bias):
        """Draw one 2x2 quad per query with the texture function `call` and
        the shader bias; returns N x 4 float32 from each quad's first pixel.
        The derivatives llvmpipe sees are the float32 differences
        (uv + d) - uv, returned by `fragment_derivatives`."""
        q = np.ascontiguousarray(queries, dtype=np.float32)
        n = len(q)
        columns = 256
        rows = (n + columns - 1) // columns
        prog, vao = self._fragment_program(call)
        # One framebuffer, grown when needed: released framebuffers leave
        # moderngl restoring a deleted binding (GL_INVALID_OPERATION on the
        # next one it makes), as there is no default framebuffer here.
        if getattr(self, "_fbo_rows", 0) < rows:
            self._fbo_rows = rows
            self._target = self.ctx.texture((2 * columns, 2 * rows), 4, dtype="f4")
            self._fbo = self.ctx.framebuffer(color_attachments=[self._target])
        fbo = self._fbo
        # The queries come from a texture, not a storage buffer: llvmpipe
        # skips buffer loads in the helper pixels of a quad that a triangle
        # edge cuts (they read 0 there), which breaks the quad's
        # derivatives; texel fetches run in every pixel of the quad.
        grid = np.zeros((rows * columns, 8), dtype=np.float32)
        grid[:n] = q
        grid[n:] = q[-1]
        qtex = self.texture([grid.reshape(rows, 2 * columns, 4)], unit=1)
        prog["columns"].value = columns
        prog["shader_bias"].value = shader_bias
        fbo.use()
        fbo.clear()
        # moderngl binds its own textures on its last unit; unit 0 keeps ours.
        self.ActiveTexture(TEXTURE0)
        vao.render(self.mgl.TRIANGLES, vertices=3)
        img = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype=np.float32)
        img = img.reshape(2 * self._fbo_rows, 2 * columns, 4)[0::2, 0::2].reshape(-1, 4)[:n].copy()
        self.delete_texture(qtex)
        self.check_error(f"fragment {call}")
        return img


def fragment_derivatives(queries):
    """The queries with the derivatives a fragment quad of run_fragment
    really has: float32 (uv + d) - uv."""
    q = np.array(queries, dtype=np.float32)
    uv = q[:, 0:2]
    q[:, 2:4] = (uv + q[:, 2:4]) - uv
    q[:, 4:6] = (uv + q[:, 4:6]) - uv
    return q


def gl_setup():
    """Mesa's llvmpipe through EGL, installed by scripts/setup-gl.sh; None
    after a "skip:" line when the packages cannot be installed here (or a
    "FAIL:" line when they are there but give no llvmpipe context)."""
    import subprocess
    from pathlib import Path

    from common import check

    root = Path(__file__).resolve().parents[2]
    r = subprocess.run(["bash", str(root / "scripts/setup-gl.sh")], capture_output=True, text=True)
    if r.returncode == 3:
        print(r.stdout.strip() or "skip: llvmpipe checks (scripts/setup-gl.sh cannot install Mesa)", flush=True)
        return None
    if r.returncode != 0:
        check(False, "scripts/setup-gl.sh installs Mesa's EGL and llvmpipe", (r.stdout + r.stderr).strip())
        return None
    try:
        gl = GL()
    except Exception as e:  # the context is the whole point: say why it failed
        check(False, "an off-screen OpenGL 4.5 context on Mesa's EGL", f"{type(e).__name__}: {e}")
        return None
    if not check("llvmpipe" in gl.renderer, "the GL context is Mesa's llvmpipe", f"{gl.renderer}, {gl.version}"):
        return None
    return gl
