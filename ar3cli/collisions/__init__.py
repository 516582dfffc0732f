"""collisions"""
