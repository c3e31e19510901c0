class TextureModder:
    """Stub: textures only matter for rendering, which the shim does not provide."""

    def __init__(self, sim):
        self.sim = sim
