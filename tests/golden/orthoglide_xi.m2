load "LIBRARY";
R = QQ[v1, v2, v3, v4, v5, v6];
I = ideal(
  v1^2-2*v1*v4+v4^2+v5^2+v6^2-4,
  v2^2-2*v2*v5+v4^2+v5^2+v6^2-4,
  v3^2-2*v3*v6+v4^2+v5^2+v6^2-4,
  -8*v1*v2*v3+8*v1*v2*v6+8*v1*v3*v5+8*v2*v3*v4);
scEliminate(I, {v1, v2, v3}, "singularity_surface");
exit 0;
