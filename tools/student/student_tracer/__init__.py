"""A student's ray tracer for Glint's course model, written from Glint's docs
alone; `tools/student/tracer.py` is its command line.  Its modules, each
importing only modules listed above it:

  mistake      the deliberate mistakes (--mistake NAME) and their switch
  vectors      vectors as tuples of three doubles
  images       PNG and Radiance .hdr readers
  textures     MIP levels, texture kinds, footprints and texture lookups
  geometry     shapes and ray intersection
  camera       the camera's basis, film points and rays
  environment  the background: a colour, a cube map or a lat-long map
  scene        reading a scene file; closest hit; the shadow offset eps
  lighting     Phong terms, light samples, shadow rays and their verdicts
  film         linear radiance to 8-bit sRGB
  integrator   tracing a ray (steps 3-11), recording explain's document
  explain      the `explain` command: a glint-explain/1 document
  stages       the `stages` command: answers to `glint grade --stages`
  cli          the command line (argparse) and its errors
"""
