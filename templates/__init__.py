"""Jinja2 templates of the report pages, installed as package data of balpipe."""
