"""Pure-Python core of ShapeMove (torch, numpy, transformers, smplx). Never imports bpy."""
