"""Reduced spring-block models of stick-slip friction."""
