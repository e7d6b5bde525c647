"""Reading and writing skyquill inputs: drawings, line-segment plans and safe corridors."""
