/* must stay an error: arrays of strings */
displacement array_string()
{
    string names[2];
}
