import os
import sys

# Make the helper modules in tests/ (chains.py) importable regardless of how pytest is invoked.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

collect_ignore = ["cmake_consumer"]
