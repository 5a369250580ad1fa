/* filterstep's optional parameters are "width" and "filter" */
displacement filterstep_param()
{
    P += filterstep(0.5, s, "blur", 0.1) * N;
}
