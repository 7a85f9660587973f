"""lifelike-mj: creatures that move like living things, by physics on MuJoCo."""

__version__ = "0.1.0"
