"""rockdem: 3D rigid-block discrete element method for rocking masonry blocks."""

__version__ = "0.1.0"
