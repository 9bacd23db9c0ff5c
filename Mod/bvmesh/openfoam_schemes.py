"""The numerical schemes and solver controls of a BVMesh OpenFOAM case, system/fvSchemes and
system/fvSolution, per solver: the pressure-based rhoPimpleFoam (local time stepping) and
rhoSimpleFoam (SIMPLE), and the density-based rhoCentralFoam. Each gives the two dictionaries'
text, {file name: body}; bvmesh.openfoam_case writes them (docs/cfd.md, Schemes).
"""


def pressure_based_schemes(lts, max_courant, model):
    """rhoPimpleFoam's dictionaries with lts (local time stepping at max_courant), else
    rhoSimpleFoam's (steady state, bounded convection, relaxed SIMPLE); model 'euler' or 'rans'."""
    ddt = "localEuler" if lts else "steadyState"
    bounded = "" if lts else "bounded "
    # The transonic pressure equation's convection carries the density across the faces. Upwind, it
    # smeared the M6's recompression away (no shock at any station, CL 0.249 on the default euler
    # grid); the TVD-limited linear scheme gives the shocks and CL 0.273 and still converges 3
    # decades with local time stepping. Measured in docs/cfd.md, where the rans run (y+ 30) swung
    # more with it and SIMPLE was measured with upwind: those keep upwind.
    pressure_convection = "limitedLinear 1" if lts and model == "euler" else "upwind"
    schemes = """ddtSchemes
{{
    default         {ddt};
}}

gradSchemes
{{
    default         Gauss linear;
    limited         cellLimited Gauss linear 1;
    grad(U)         $limited;
    grad(e)         $limited;
    grad(nuTilda)   $limited;
}}

divSchemes
{{
    default         none;
    div(phi,U)      {bounded}Gauss linearUpwind limited;
    div(phi,e)      {bounded}Gauss linearUpwind limited;
    div(phi,K)      {bounded}Gauss linearUpwind limited;
    div(phi,Ekp)    {bounded}Gauss linearUpwind limited;
    div(phi,nuTilda) {bounded}Gauss upwind;
    div(phid,p)     Gauss {pressure_convection};
    div(phiv,p)     Gauss upwind;
    div((phi|interpolate(rho)),p) {bounded}Gauss upwind;
    div(((rho*nuEff)*dev2(T(grad(U))))) Gauss linear;
}}

laplacianSchemes
{{
    default         Gauss linear limited corrected 0.5;
}}

interpolationSchemes
{{
    default         linear;
}}

snGradSchemes
{{
    default         limited corrected 0.5;
}}

wallDist
{{
    method          meshWave;
}}
""".format(ddt=ddt, bounded=bounded, pressure_convection=pressure_convection)

    solvers = """solvers
{
    p
    {
        solver          GAMG;
        smoother        GaussSeidel;
        tolerance       1e-12;
        relTol          0.05;
    }
    "(U|e|nuTilda|rho)"
    {
        solver          PBiCGStab;
        preconditioner  DILU;
        tolerance       1e-12;
        relTol          0.1;
    }
    pFinal
    {
        $p;
    }
    "(U|e|nuTilda|rho)Final"
    {
        $U;
    }
}
"""
    if lts:
        algorithm = """PIMPLE
{{
    transonic       yes;
    momentumPredictor yes;
    nOuterCorrectors 1;
    nCorrectors     2;
    nNonOrthogonalCorrectors 1;  // the tip faces are > 70 deg non-orthogonal
    pMinFactor      0.1;
    pMaxFactor      2;
    // Measured on coarse M6 grids (docs/cfd.md): maxCo 2 converges to machine zero, 5 stalls;
    // OpenFOAM's default smoothing (0.02) keeps the far field's steps tiny for thousands of steps.
    maxCo           {max_courant!r};
    rDeltaTSmoothingCoeff 1;
    rDeltaTDampingCoeff 1;
    maxDeltaT       1;
}}

relaxationFactors
{{
    equations
    {{
        ".*"        1;
    }}
}}
""".format(max_courant=max_courant)
    else:
        algorithm = """SIMPLE
{
    transonic       yes;
    consistent      no;
    nNonOrthogonalCorrectors 0;
    pMinFactor      0.1;
    pMaxFactor      2;
}

relaxationFactors
{
    fields
    {
        p               1;
        rho             1;
    }
    equations
    {
        p               0.3;
        U               0.5;
        e               0.5;
        nuTilda         0.5;
    }
}
"""
    return {"fvSchemes": schemes, "fvSolution": solvers + "\n" + algorithm}


def central_schemes():
    """rhoCentralFoam's dictionaries (an euler case only)."""
    # Kurganov & Tadmor's central-upwind fluxes from van Leer-limited reconstructions; the Laplacian
    # and normal-gradient corrections limited as above for the tip's non-orthogonal faces (an
    # inviscid case uses them only through the function objects).
    schemes = """fluxScheme      Kurganov;

ddtSchemes
{
    default         localEuler;
}

gradSchemes
{
    default         Gauss linear;
}

divSchemes
{
    default         none;
    div(tauMC)      Gauss linear;
}

laplacianSchemes
{
    default         Gauss linear limited corrected 0.5;
}

interpolationSchemes
{
    default         linear;
    reconstruct(rho) vanLeer;
    reconstruct(U)  vanLeerV;
    reconstruct(T)  vanLeer;
}

snGradSchemes
{
    default         limited corrected 0.5;
}
"""
    # The conserved variables are updated explicitly; U and e would be solved only with a viscosity,
    # which an euler case (the only model written for this solver) does not have.
    solution = """solvers
{
    "(rho|rhoU|rhoE)"
    {
        solver          diagonal;
    }
}
"""
    return {"fvSchemes": schemes, "fvSolution": solution}
