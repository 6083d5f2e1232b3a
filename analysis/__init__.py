"""Reduction of event catalogs to the statistics of Ohmura & Kawamura (2007), and their figures."""
