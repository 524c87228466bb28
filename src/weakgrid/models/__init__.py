"""weakgrid.models"""
