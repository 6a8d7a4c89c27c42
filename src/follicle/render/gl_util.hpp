#pragma once
// Small OpenGL helpers shared by the renderer's passes (internal to the render module; needs
// GL_GLEXT_PROTOTYPES and a current GL 3.3 core context).
#include <GL/gl.h>
#include <GL/glext.h>

#include <string>

#include "follicle/core/error.hpp"
#include "follicle/core/types.hpp"
#include "follicle/render/shaders_gl.hpp"

namespace follicle::render::gl {

inline GLuint compile(GLenum type, const std::string& src, const char* name) {
  GLuint s = glCreateShader(type);
  const char* p = src.c_str();
  glShaderSource(s, 1, &p, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {0};
    glGetShaderInfoLog(s, sizeof(log) - 1, nullptr, log);
    glDeleteShader(s);
    fail("render: cannot compile shader {}: {}", name, log);
  }
  return s;
}

/// "#version 330 core" + defines before every stage; with `lights` the lights uniform block
/// goes before the fragment shader.
inline GLuint link_program(const char* name, const std::string& defines, const char* vs,
                           const char* fs, const char* gs = nullptr, bool lights = false) {
  const std::string head = std::string("#version 330 core\n") + defines;
  const std::string lb = lights ? glsl::kLightsBlock : "";
  GLuint v = compile(GL_VERTEX_SHADER, head + vs, name);
  GLuint f = compile(GL_FRAGMENT_SHADER, head + lb + fs, name);
  GLuint g = gs ? compile(GL_GEOMETRY_SHADER, head + gs, name) : 0;
  GLuint p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  if (g) glAttachShader(p, g);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  if (g) glDeleteShader(g);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {0};
    glGetProgramInfoLog(p, sizeof(log) - 1, nullptr, log);
    glDeleteProgram(p);
    fail("render: cannot link shader program {}: {}", name, log);
  }
  return p;
}

inline void set_mat4(GLuint p, const char* n, const Mat4& m) {
  const Eigen::Matrix4f f = m.cast<float>();  // Eigen is column-major like GL
  glUniformMatrix4fv(glGetUniformLocation(p, n), 1, GL_FALSE, f.data());
}
inline void set_mat3(GLuint p, const char* n, const Mat3& m) {
  const Eigen::Matrix3f f = m.cast<float>();
  glUniformMatrix3fv(glGetUniformLocation(p, n), 1, GL_FALSE, f.data());
}
inline void set_vec3(GLuint p, const char* n, const Vec3& v) {
  glUniform3f(glGetUniformLocation(p, n), float(v.x()), float(v.y()), float(v.z()));
}
inline void set_f(GLuint p, const char* n, double v) {
  glUniform1f(glGetUniformLocation(p, n), float(v));
}
inline void set_i(GLuint p, const char* n, int v) {
  glUniform1i(glGetUniformLocation(p, n), v);
}

}  // namespace follicle::render::gl
