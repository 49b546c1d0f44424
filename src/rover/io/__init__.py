"""Reading and writing videos, frame folders, dataset directories and robot datasets."""
