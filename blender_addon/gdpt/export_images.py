# Blender images -> scene-linear RGBA arrays in the scene (one copy per image per render).
#
# image.pixels of a float image (EXR, HDR, float generated) is already scene linear: Blender
# linearises float buffers on load. Byte images keep their file encoding, so they are converted
# by the core from the image's colour space (OCIO, Blender's config) unless it is non-colour data.

import numpy as np

# Colour spaces whose values are used as they are.
_LINEAR_SPACES = {"Non-Color", "Linear", "Raw", "Linear Rec.709", "scene_linear", "XYZ"}


class ImageCache:
    def __init__(self, builder, warn):
        self.builder = builder
        self.warn = warn
        self.index = {}

    def get(self, image):
        """Index of `image` in the scene, -1 (with a warning) when it has no pixels."""
        if image is None:
            return -1
        key = image.as_pointer()
        if key in self.index:
            return self.index[key]
        index = self._add(image)
        self.index[key] = index
        return index

    def _add(self, image):
        width, height = image.size[0], image.size[1]  # reading the size loads the image
        if width == 0 or height == 0 or image.channels == 0:
            self.warn(f"image '{image.name}' has no pixels (missing file?); using magenta")
            return -1
        channels = image.channels
        pixels = np.empty(width * height * channels, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        if channels != 4:
            flat = pixels.reshape(-1, channels)
            rgba = np.ones((width * height, 4), dtype=np.float32)
            if channels >= 3:
                rgba[:, :3] = flat[:, :3]
            else:
                rgba[:, :3] = flat[:, :1]
            pixels = rgba.ravel()
        space = image.colorspace_settings.name
        if image.is_float or space in _LINEAR_SPACES:
            space = ""  # already scene linear (or data)
        return self.builder.add_image(image.name, width, height, pixels, space)
