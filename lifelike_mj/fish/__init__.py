"""Tropical fish (Satoi, Nakadai & Hoshino 2015): motion units, tracks and their measures."""
