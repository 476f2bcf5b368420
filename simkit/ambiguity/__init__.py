"""ambiguity"""
