"""softbench: a MuJoCo + dm_control benchmark suite for controllers of modular soft robot arms."""

__version__ = "0.1.0"
