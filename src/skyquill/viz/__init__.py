"""Figures. The only package that imports matplotlib (with the Agg backend)."""
